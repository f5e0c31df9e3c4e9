//! A stress case of issue 35, bounded: the lily's first petal alone at the
//! paper's resolution with its inner growth along the growth direction
//! doubled (dg doubled, the e, w and w_in maps halved) rolls into a scroll.
//! The run must give only keyframes in which no two of its triangles cross
//! (checked here by testing every pair), and end either at its last
//! keyframe or with a stop that names the crossing; it used to go on
//! through itself to keyframe 100 and end with success. The other cases run
//! with `cargo run --release -p anthesis-garden --example stress`.

use anthesis_garden::flowers::flower_at_resolution;
use anthesis_maps::MapKind;
use anthesis_mesh::Mesh;
use anthesis_sim::{Selection, SimError, Simulation};

#[test]
fn the_lily_petal_painted_to_roll_into_a_scroll_never_shows_a_crossing() {
    let mut project = flower_at_resolution("lily", 1.0)
        .expect("the lily")
        .expect("it builds");
    for t in &mut project.flower.templates {
        t.dg *= 2.0;
        for key in t.maps.keys_mut() {
            if let Some(dg) = &mut key.dg {
                *dg *= 2.0;
            }
            for kind in [MapKind::EGrowth, MapKind::WGrowth, MapKind::WGrowthIn] {
                for v in key.maps.scalar_mut(kind).values_mut() {
                    *v *= 0.5;
                }
            }
        }
    }
    let mut sim = Simulation::new(&project, &Selection::Only(0)).expect("valid");
    let mesh = project.flower.templates[project.flower.organs[0].template]
        .mesh
        .clone();
    let mut shown = vec![sim.bud()];
    let error = loop {
        if sim.finished() {
            break None;
        }
        match sim.step(&|| false, &mut |_| {}) {
            Ok(k) => shown.push(k),
            Err(error) => break Some(error),
        }
    };
    for k in &shown {
        let at = Mesh {
            positions: k.positions_in_world[0].clone(),
            ..mesh.clone()
        };
        assert_eq!(
            anthesis_bud::self_intersections(&at),
            Vec::<[usize; 2]>::new(),
            "keyframe {} was shown with crossing triangles",
            k.index
        );
    }
    match &error {
        None => {}
        Some(SimError::Crossed(found)) => {
            assert_eq!(found.keyframe as usize, shown.len());
            assert_eq!(found.organs, vec![0]);
        }
        Some(other) => panic!("stopped otherwise than at a crossing: {other}"),
    }
    println!(
        "{} keyframes shown, then {}",
        shown.len() - 1,
        error.map_or("the end".to_string(), |e| e.to_string())
    );
}
