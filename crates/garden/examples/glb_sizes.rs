//! Simulates the built-in lily and prints the .glb size in every encoding,
//! with the receptacle as a static mesh:
//! `cargo run --release -p anthesis-garden --example glb_sizes [-- OUT.glb]`.

use anthesis_export::{GlbOptions, Track, glb_size_report};
use anthesis_sim::{Selection, run};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let project = anthesis_garden::builtin_lily()?;
    let mut frames: Vec<Vec<Vec<glam::DVec3>>> = Vec::new();
    let sim = run(&project, &Selection::All, &mut |_, k| {
        frames.push(k.positions.clone())
    })?;
    let mut tracks: Vec<Track> = sim
        .organs()
        .iter()
        .enumerate()
        .map(|(i, name)| Track {
            name: name.to_string(),
            triangles: sim.triangles(i).to_vec(),
            uvs: sim.uvs(i).to_vec(),
            base_color: sim.color(i),
            keyframes: frames.iter().map(|f| f[i].clone()).collect(),
            base_color_png: None,
        })
        .collect();
    let receptacle = anthesis_garden::receptacle_mesh(2.2, 1.5);
    tracks.push(Track {
        name: "receptacle".into(),
        triangles: receptacle.triangles.clone(),
        uvs: receptacle.uvs.clone(),
        base_color: [0.35, 0.55, 0.25, 1.0],
        keyframes: vec![receptacle.positions.clone()],
        base_color_png: None,
    });
    let report = glb_size_report(&tracks, &GlbOptions::default())?;
    println!("{report}");
    // With a path argument, also write the default (dense) file there.
    if let Some(path) = std::env::args().nth(1) {
        anthesis_export::write_glb(path.as_ref(), &tracks, &GlbOptions::default(), &mut |_| {})?;
    }
    Ok(())
}
