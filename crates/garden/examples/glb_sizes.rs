//! Simulates the built-in lily and prints the .glb size in every encoding,
//! with the tracks every export of a flower has (the organs and the
//! receptacle, `anthesis_export::flower_tracks`):
//! `cargo run --release -p anthesis-garden --example glb_sizes [-- OUT.glb]`.

use anthesis_export::{GlbOptions, flower_tracks, glb_size_report};
use anthesis_sim::{Selection, run};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let project = anthesis_garden::builtin_lily()?;
    let mut frames: Vec<Vec<Vec<glam::DVec3>>> = Vec::new();
    let sim = run(&project, &Selection::All, &mut |_, k| {
        frames.push(k.positions_in_world.clone())
    })?;
    let organs = Selection::All.organs(sim.organs().len());
    let tracks = flower_tracks(
        &project.flower,
        &organs,
        frames.iter().map(Vec::as_slice),
        0,
    )?;
    let report = glb_size_report(&tracks, &GlbOptions::default())?;
    println!("{report}");
    // With a path argument, also write the default (dense) file there.
    if let Some(path) = std::env::args().nth(1) {
        anthesis_export::write_glb(path.as_ref(), &tracks, &GlbOptions::default(), &mut |_| {})?;
    }
    Ok(())
}
