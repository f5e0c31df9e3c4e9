//! Converged shapes (the bounded CI slice of the refinement study; the full
//! tables: `cargo run --release -p anthesis-garden --example refine`): the
//! lily petal run alone at the default flowers' resolution ends within 5 %
//! of its midrib length of the same petal meshed at half the edge (about
//! four times the particles), same bud surface, same maps.

use anthesis_garden::flowers::{EDGE_SCALE, flower_at_resolution};
use anthesis_garden::shape::{UvSampler, organ_shape};
use anthesis_sim::{Selection, run};
use glam::{DVec2, DVec3};

/// The petal's final world positions at `edge_scale`, and its mesh.
fn final_petal(edge_scale: f64) -> (anthesis_mesh::Mesh, Vec<DVec3>) {
    let project = flower_at_resolution("lily", edge_scale)
        .expect("a default flower")
        .expect("builds");
    let mut last = Vec::new();
    run(&project, &Selection::Only(0), &mut |_, keyframe| {
        last.clone_from(&keyframe.positions_in_world[0]);
    })
    .expect("runs");
    (project.flower.templates[0].mesh.clone(), last)
}

#[test]
fn the_lily_petal_at_the_default_resolution_is_within_5_percent_of_four_times_the_particles() {
    let (coarse_mesh, coarse) = final_petal(EDGE_SCALE);
    let (fine_mesh, fine) = final_petal(0.5 * EDGE_SCALE);
    assert!(
        fine_mesh.vertex_count() > 3 * coarse_mesh.vertex_count(),
        "{} vs {} particles",
        fine_mesh.vertex_count(),
        coarse_mesh.vertex_count()
    );
    let length = organ_shape(&fine_mesh, &fine)
        .expect("measurable")
        .midrib_length;
    let (coarse_at, fine_at) = (UvSampler::new(&coarse_mesh), UvSampler::new(&fine_mesh));
    // The tip, the middle of the midrib and two lamina points.
    for (u, v) in [(0.5, 1.0), (0.5, 0.5), (0.2, 0.7), (0.8, 0.7)] {
        let uv = DVec2::new(u, v);
        let apart = coarse_at
            .point(&coarse, uv)
            .expect("on the petal")
            .distance(fine_at.point(&fine, uv).expect("on the petal"));
        eprintln!("({u}, {v}): {:.2} % of the midrib", 100.0 * apart / length);
        assert!(
            apart < 0.05 * length,
            "({u}, {v}) lies {:.1} % of the midrib length from the finer run",
            100.0 * apart / length
        );
    }
}
