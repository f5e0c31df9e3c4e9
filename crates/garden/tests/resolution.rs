//! The shipped flowers at another resolution (`anthesis_flower::resolution`):
//! every template remeshes coarser and finer than built, keeps its outline
//! and base, and a painted flower still simulates.

use anthesis_bud::quality;
use anthesis_flower::MIN_BASE_PARTICLES;
use anthesis_flower::Resolution;
use anthesis_flower::resolution::{ResolutionProblem, resolve};
use anthesis_garden::{builtin, builtin_lily, builtin_names};
use anthesis_sim::{Selection, Simulation};

#[test]
fn every_shipped_template_remeshes_coarser_and_finer() {
    // Templates whose base is too narrow to keep three particles (what
    // attaches an organ) at 1.5 times their edge: refused, naming the
    // edge, instead of a run that cannot start.
    let mut refused = Vec::new();
    for name in builtin_names() {
        let project = builtin(name).expect("listed").expect("loads");
        for template in &project.flower.templates {
            let built = quality(&template.mesh);
            for factor in [1.5, 0.6] {
                let edge = built.mean_edge * factor;
                let mut at = project.clone();
                at.settings.resolution = Resolution::MeanEdge(edge);
                let resolved = match resolve(&at) {
                    Ok(resolved) => resolved,
                    Err(e)
                        if factor > 1.0
                            && matches!(
                                e.problem,
                                ResolutionProblem::TooFewBaseParticles { particles, .. }
                                    if particles < MIN_BASE_PARTICLES
                            ) =>
                    {
                        refused.push(format!("{name}/{}", template.name));
                        continue;
                    }
                    Err(e) => panic!("{name}: {e}"),
                };
                let index = project
                    .flower
                    .templates
                    .iter()
                    .position(|t| t.name == template.name)
                    .expect("template");
                let mesh = &resolved.flower.templates[index].mesh;
                let q = quality(mesh);
                assert!(
                    (q.mean_edge - edge).abs() < 0.1 * edge,
                    "{name}/{}: edge {edge:.3} gave {:.3}",
                    template.name,
                    q.mean_edge
                );
                assert!(q.min_angle_deg >= 20.0, "{name}/{}: {q:?}", template.name);
                // Area kept within what chords across a curved surface lose.
                let (old, new) = (template.mesh.area(), mesh.area());
                assert!(
                    (new - old).abs() < 0.03 * old,
                    "{name}/{}: area {old:.3} -> {new:.3}",
                    template.name
                );
                // The base still attaches it, the tip is where it was.
                assert!(template.base_region.particles(mesh).len() >= MIN_BASE_PARTICLES);
                let tip = |m: &anthesis_mesh::Mesh| {
                    let i = (0..m.vertex_count())
                        .max_by(|&a, &b| m.uvs[a].y.total_cmp(&m.uvs[b].y))
                        .expect("vertices");
                    m.positions[i]
                };
                assert!(
                    tip(mesh).distance(tip(&template.mesh)) < 1e-9,
                    "{name}/{}: the tip moved",
                    template.name
                );
            }
        }
    }
    // The five-petal start's petal: 4 base particles as built, 2 at 1.5
    // times its edge.
    assert_eq!(refused, ["five-petal/petal"]);
}

#[test]
fn the_painted_lily_simulates_after_remeshing() {
    let mut lily = builtin_lily().expect("the lily loads");
    let built = quality(&lily.flower.templates[0].mesh).mean_edge;
    lily.settings.resolution = Resolution::MeanEdge(1.4 * built);
    lily.settings.keyframes = 3;
    let resolved = resolve(&lily).expect("remeshes");
    let mut sim = Simulation::new(&resolved, &Selection::Only(0)).expect("starts");
    let bud = sim.bud();
    let particles = resolved.flower.template_of(0).mesh.vertex_count();
    assert_eq!(bud.positions_in_world[0].len(), particles);
    assert_ne!(particles, lily.flower.template_of(0).mesh.vertex_count());
    let mut last = bud.positions_in_world[0].clone();
    for _ in 0..3 {
        let keyframe = sim.step(&|| false, &mut |_| {}).expect("converges");
        let moved = keyframe.positions_in_world[0]
            .iter()
            .zip(&last)
            .map(|(a, b)| a.distance(*b))
            .fold(0.0, f64::max);
        // The painted growth moves the petal.
        assert!(moved > 1e-6, "keyframe {} did not move", keyframe.index);
        assert!(keyframe.positions_in_world[0].iter().all(|p| p.is_finite()));
        last = keyframe.positions_in_world[0].clone();
    }
}
