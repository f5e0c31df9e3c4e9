//! A fitting target the growth simulation did not make (issue 15 item 5,
//! "a two-state open shape"): the built-in lily's petal-1 in the bud, each
//! particle turned outwards about the base's x axis by `1.3 v²` radians and
//! widened by `1 + 0.15 v` (v from base to tip), in world coordinates with
//! the bud's vertex order, as `anthesis fit --target` takes it.
//!
//! `cargo run --release -p anthesis-fit --example reflexed_target -- OPEN.obj`
//! then `anthesis fit builtin:lily --organ petal-1 --target OPEN.obj --out DIR`.

use anthesis_sim::{Selection, Simulation};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .ok_or("usage: reflexed_target OPEN.obj")?;
    let project = anthesis_garden::builtin_lily()?;
    let organ = project
        .flower
        .organs
        .iter()
        .position(|o| o.name == "petal-1")
        .ok_or("no petal-1")?;
    let bud = Simulation::new(&project, &Selection::Only(organ))?.bud();
    let mesh = &project.flower.template_of(organ).mesh;
    let positions = &bud.positions_in_world[0];
    let base: Vec<_> = positions
        .iter()
        .zip(&mesh.uvs)
        .filter(|(_, uv)| uv.y < 0.03)
        .map(|(p, _)| *p)
        .collect();
    let centre = base.iter().sum::<glam::DVec3>() / base.len().max(1) as f64;
    let open: Vec<glam::DVec3> = positions
        .iter()
        .zip(&mesh.uvs)
        .map(|(p, uv)| {
            let turned = glam::DQuat::from_rotation_x(1.3 * uv.y * uv.y) * (*p - centre);
            let widened = glam::DVec3::new(turned.x * (1.0 + 0.15 * uv.y), turned.y, turned.z);
            centre + widened
        })
        .collect();
    let target = anthesis_mesh::Mesh {
        positions: open,
        ..mesh.clone()
    };
    let text = format!("o petal-1\n{}", anthesis_mesh::obj_string(&target));
    std::fs::write(&out, text)?;
    eprintln!("wrote {out}");
    Ok(())
}
