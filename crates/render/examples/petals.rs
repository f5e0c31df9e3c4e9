//! Renders three test petals on a receptacle to a PNG and prints the time.
//!
//! `cargo run -p anthesis-render --example petals -- /tmp/petals.png 800 [azimuth_deg elevation_deg]`

use std::time::Instant;

use anthesis_mesh::generate::test_petal;
use anthesis_render::{Camera, OffscreenRenderer, OrganMesh, organs_bounds_in_world};
use glam::{DMat3, DVec3};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args.next().unwrap_or_else(|| "/tmp/petals.png".into());
    let size: u32 = args.next().map_or(Ok(800), |s| s.parse())?;

    let petal = test_petal(10.0, 5.0, 14, 28);
    // Linear RGBA (pale pink, white, pink).
    let colours = [
        [0.96, 0.6, 0.71, 1.0],
        [0.93, 0.93, 0.89, 1.0],
        [0.89, 0.34, 0.52, 1.0],
    ];
    let azimuth_deg: f64 = args.next().map_or(Ok(25.0), |s| s.parse())?;
    let elevation_deg: f64 = args.next().map_or(Ok(35.0), |s| s.parse())?;
    let receptacle_radius = 1.0;
    let tilt_outwards = 35_f64.to_radians();
    let organs: Vec<OrganMesh> = (0..3)
        .map(|i| {
            let azimuth = f64::from(i) * 120_f64.to_radians();
            // Template frame -> world: tilt outwards about +X, move onto the
            // receptacle rim (+Z, away from the axis), turn about +Y.
            let tilt = DMat3::from_rotation_x(tilt_outwards);
            let turn = DMat3::from_rotation_y(azimuth);
            let positions: Vec<DVec3> = petal
                .positions
                .iter()
                .map(|&p| turn * (tilt * p + DVec3::new(0.0, 0.0, receptacle_radius)))
                .collect();
            OrganMesh::from_positions(&positions, &petal.triangles, colours[i as usize])
        })
        .collect();
    let (lo, hi) = organs_bounds_in_world(&organs).ok_or("no vertices")?;

    let started = Instant::now();
    let mut renderer = OffscreenRenderer::new()?;
    println!(
        "adapter {} ({:?}), {}x MSAA, set-up {:.0} ms",
        renderer.adapter_info().name,
        renderer.adapter_info().backend,
        renderer.format().sample_count,
        started.elapsed().as_secs_f64() * 1e3
    );
    let camera = Camera::framing(lo, hi, azimuth_deg, elevation_deg);
    for round in 0..3 {
        let started = Instant::now();
        let image = renderer.render(&organs, &camera, size, size)?;
        println!(
            "render {round}: {size}x{size} in {:.0} ms",
            started.elapsed().as_secs_f64() * 1e3
        );
        if round == 0 {
            image.save(&path)?;
        }
    }
    println!("wrote {path}");
    Ok(())
}
