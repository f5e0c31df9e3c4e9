//! Simulates the built-in lily and prints the .glb size in every encoding,
//! with the tracks every export of a flower has (the organs and the
//! receptacle), from the batch run `anthesis simulate` makes
//! (`anthesis_sim::batch`):
//! `cargo run --release -p anthesis-garden --example glb_sizes [-- OUT.glb]`.

use anthesis_export::{GlbOptions, glb_size_report};
use anthesis_sim::Selection;
use anthesis_sim::batch::{self, Format};
use anthesis_sim::crossing::OnCrossing;
use anthesis_sim::memory::KeyframeCost;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The batch run `anthesis simulate --out` makes.
    let project = batch::prepare(
        &anthesis_garden::builtin_lily()?,
        &Selection::All,
        KeyframeCost::Glb,
        Some(0),
    )?;
    let run = batch::simulate(
        &project,
        &Selection::All,
        OnCrossing::Stop,
        &|| false,
        &mut |_, _| {},
    )?;
    if let Some(failure) = run.stepped.failure {
        return Err(failure.into());
    }
    let tracks = run.tracks(&project, &Selection::All, 0)?;
    let report = glb_size_report(&tracks, &GlbOptions::default())?;
    println!("{report}");
    // With a path argument, also write the default (dense) file there.
    if let Some(path) = std::env::args().nth(1) {
        batch::write(
            path.as_ref(),
            Format::Glb,
            &tracks,
            &GlbOptions::default(),
            &mut |_| {},
        )?;
    }
    Ok(())
}
