//! Simulates the built-in lily and prints the .glb size in every encoding,
//! with the receptacle as a static mesh, as `anthesis simulate --out` writes it:
//! `cargo run --release -p anthesis-garden --example glb_sizes [-- OUT.glb]`.

use anthesis_export::{GlbOptions, Track, TrackLook, glb_size_report, organ_tracks};
use anthesis_sim::{Selection, run};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let project = anthesis_garden::builtin_lily()?;
    let mut frames: Vec<Vec<Vec<glam::DVec3>>> = Vec::new();
    let sim = run(&project, &Selection::All, &mut |_, k| {
        frames.push(k.positions_in_world.clone())
    })?;
    let names = sim.organs();
    let looks = names
        .iter()
        .enumerate()
        .map(|(i, name)| TrackLook::new(name, sim.triangles(i), sim.uvs(i), sim.color(i)));
    let mut tracks = organ_tracks(looks, frames.iter().map(Vec::as_slice));
    tracks.push(Track::still(
        "receptacle",
        anthesis_garden::receptacle_for(&project.flower),
        anthesis_garden::RECEPTACLE_COLOR,
    ));
    let report = glb_size_report(&tracks, &GlbOptions::default())?;
    println!("{report}");
    // With a path argument, also write the default (dense) file there.
    if let Some(path) = std::env::args().nth(1) {
        anthesis_export::write_glb(path.as_ref(), &tracks, &GlbOptions::default(), &mut |_| {})?;
    }
    Ok(())
}
