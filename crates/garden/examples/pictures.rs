//! Simulates a default flower, prints its shape descriptors at chosen
//! keyframes and renders those keyframes, side view above 3/4 view, tiled
//! into one PNG.
//!
//! `cargo run --release -p anthesis-garden --example pictures -- NAME OUT.png [--frames 0,1,25,50,75,100] [--tile 300] [--zoom 0.8] [--views 0:5,30:40] [--side-only] [--top] [--only ORGAN] [--no-midrib-warping] [--edge-scale S]`
//!
//! `--edge-scale S` remeshes the buds at `S` times Table 1's mean edge (the
//! default flowers: 0.6; 0.3 gives about four times the particles).
//!
//! The README's pictures are made with
//! `--frames 1,25,50,75,100 --views 25:20 --tile 300`.

use std::time::Instant;

use anthesis_garden::{flowers, shape};
use anthesis_render::{Camera, OffscreenRenderer, OrganMesh, organs_bounds_in_world};
use anthesis_sim::{Selection, run};
use glam::DVec3;
use image::{GenericImage, RgbaImage};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let name = args.next().ok_or("give a flower name")?;
    let out = args.next().ok_or("give an output PNG")?;
    let mut frames: Vec<u32> = vec![1, 25, 50, 75, 100];
    let mut tile = 300u32;
    let mut zoom = 0.8;
    let mut only: Option<usize> = None;
    let mut no_midrib = false;
    let mut edge_scale = flowers::EDGE_SCALE;
    let mut views: Vec<(f64, f64)> = vec![(0.0, 5.0), (30.0, 40.0)];
    while let Some(flag) = args.next() {
        match flag.as_str() {
            "--frames" => {
                frames = args
                    .next()
                    .ok_or("--frames needs a list")?
                    .split(',')
                    .map(str::parse)
                    .collect::<Result<_, _>>()?;
            }
            "--tile" => tile = args.next().ok_or("--tile needs a size")?.parse()?,
            "--zoom" => zoom = args.next().ok_or("--zoom needs a factor")?.parse()?,
            "--only" => only = Some(args.next().ok_or("--only needs an organ index")?.parse()?),
            "--no-midrib-warping" => no_midrib = true,
            "--edge-scale" => {
                edge_scale = args.next().ok_or("--edge-scale needs a number")?.parse()?;
            }
            "--side-only" => views = vec![(0.0, 5.0)],
            "--top" => views.push((0.0, 85.0)),
            "--views" => {
                // AZIMUTH:ELEVATION,… in degrees, one row each.
                views = args
                    .next()
                    .ok_or("--views needs a list")?
                    .split(',')
                    .map(|view| -> Result<(f64, f64), Box<dyn std::error::Error>> {
                        let (azimuth, elevation) =
                            view.split_once(':').ok_or("a view is AZIMUTH:ELEVATION")?;
                        Ok((azimuth.parse()?, elevation.parse()?))
                    })
                    .collect::<Result<_, _>>()?;
            }
            other => return Err(format!("unknown flag {other}").into()),
        }
    }
    println!(
        "half spans: lily petal {:.1} sepal {:.1} eustoma {:.1}",
        flowers::lily_petal_bud().half_span_deg(),
        flowers::lily_sepal_bud().half_span_deg(),
        flowers::eustoma_petal_bud().half_span_deg()
    );
    let project = flowers::flower_at_resolution(&name, edge_scale).ok_or("unknown flower")??;
    for t in &project.flower.templates {
        let q = anthesis_bud::quality(&t.mesh);
        println!(
            "template {}: {} particles, {} triangles, {} edges, mean edge {:.2}, min angle {:.1}, base v <= {:.3}",
            t.name,
            q.vertices,
            q.triangles,
            q.edges,
            q.mean_edge,
            q.min_angle_deg,
            t.base_region.v_max
        );
    }
    println!("overlaps: {:?}", project.flower.overlaps);
    let last = frames.iter().copied().max().unwrap_or(0);
    let mut project = project;
    if no_midrib {
        for t in &mut project.flower.templates {
            t.maps = flowers::lily_maps(flowers::LilyExcess::PETAL.without_midrib_warping())?;
        }
    }
    let selection = only.map_or(Selection::All, Selection::Only);
    let simulated: Vec<usize> =
        only.map_or_else(|| (0..project.flower.organs.len()).collect(), |i| vec![i]);
    project.settings.keyframes = last;
    let started = Instant::now();
    let mut kept: Vec<(u32, Vec<Vec<DVec3>>)> = Vec::new();
    let meshes: Vec<_> = simulated
        .iter()
        .map(|&i| project.flower.template_of(i).mesh.clone())
        .collect();
    // Each organ's colour, or white times its template's colour map (as the
    // app and `anthesis render` draw it): both sides' maps side by side when
    // they differ (the lily's spots are inside only).
    let looks: Vec<_> = simulated
        .iter()
        .map(|&i| {
            let template = project.flower.template_of(i);
            match &template.colouring {
                None => (template.colour, None),
                Some(_) => {
                    let (w, h) = template.colour_image_size();
                    let uvs: Vec<[f32; 2]> = template
                        .mesh
                        .uvs
                        .iter()
                        .map(|uv| uv.as_vec2().to_array())
                        .collect();
                    let two_sided = template.is_two_sided();
                    let image = if two_sided {
                        template.colour_atlas(w, h)
                    } else {
                        template.colour_image(w, h)
                    };
                    ([1.0; 4], Some((uvs, std::sync::Arc::new(image), two_sided)))
                }
            }
        })
        .collect();
    let result = run(&project, &selection, &mut |_, keyframe| {
        if frames.contains(&keyframe.index) {
            let s = shape::flower_shape(
                meshes
                    .iter()
                    .zip(&keyframe.positions_in_world)
                    .map(|(m, p)| (m, p.as_slice())),
            );
            if let Err(e) = &s {
                println!("kf {}: {e}", keyframe.index);
            }
            if let Ok(s) = s {
                let m = s.mean;
                println!(
                    "kf {:3}: angles {:6.1} {:6.1} {:6.1} turn mid {:6.1} lam {:6.1} cup {:6.3} swell {:6.3} radius {:5.1} {:5.1} {:5.1} {:5.1} height {:5.1} {:5.1} {:5.1} {:5.1} len {:5.1} it {} contact {} pushed {}",
                    keyframe.index,
                    m.midrib_angles_deg[0],
                    m.midrib_angles_deg[1],
                    m.midrib_angles_deg[2],
                    m.midrib_turning_deg,
                    m.lamina_turning_deg,
                    m.cupping,
                    m.swelling,
                    m.radius_profile[0],
                    m.radius_profile[1],
                    m.radius_profile[2],
                    m.radius_profile[3],
                    m.height_profile[0],
                    m.height_profile[1],
                    m.height_profile[2],
                    m.height_profile[3],
                    m.midrib_length,
                    keyframe.stats.iterations,
                    keyframe.stats.contact_particles,
                    keyframe.stats.pushed_particles
                );
            }
            kept.push((keyframe.index, keyframe.positions_in_world.clone()));
        }
    });
    println!(
        "simulated {last} keyframes in {:.1} s",
        started.elapsed().as_secs_f64()
    );
    if let Err(e) = &result {
        println!("simulation stopped: {e}");
    }
    let pieces = anthesis_flower::parts::part_pieces(&project.flower);
    let mut renderer = OffscreenRenderer::new()?;
    let columns = kept.len() as u32;
    let rows = if only.is_some() {
        3
    } else {
        views.len() as u32
    };
    let mut sheet = RgbaImage::new(tile * columns, tile * rows);
    let scenes: Vec<Vec<OrganMesh>> = kept
        .iter()
        .map(|(index, positions)| {
            let mut organs: Vec<OrganMesh> = positions
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    let (colour, texture) = &looks[i];
                    let mesh = OrganMesh::from_positions(p, &meshes[i].triangles, *colour);
                    match texture {
                        Some((uvs, image, true)) => {
                            mesh.with_two_sided_texture(uvs.clone(), image.clone())
                        }
                        Some((uvs, image, false)) => mesh.with_texture(uvs.clone(), image.clone()),
                        None => mesh,
                    }
                })
                .collect();
            // The receptacle, stamens, pistil and stem, with the whole flower.
            if only.is_none() {
                organs.extend(pieces.iter().map(|piece| {
                    OrganMesh::from_positions(
                        &piece.positions_at(*index),
                        &piece.mesh.triangles,
                        piece.colour,
                    )
                }));
            }
            organs
        })
        .collect();
    // Frame every keyframe the same way: a box about the axis that holds
    // them all.
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for organs in &scenes {
        let (l, h) = organs_bounds_in_world(organs).ok_or("empty")?;
        lo = lo.min(l);
        hi = hi.max(h);
    }
    let (lo, hi) = if only.is_some() {
        // One organ: frame it tightly, seen from the side of its bending
        // plane, from above and from the front.
        views = vec![(90.0, 5.0), (0.0, 85.0), (0.0, 5.0)];
        (lo, hi)
    } else {
        let reach = lo.x.abs().max(hi.x.abs()).max(lo.z.abs()).max(hi.z.abs());
        (
            DVec3::new(-reach, lo.y, -reach),
            DVec3::new(reach, hi.y, reach),
        )
    };
    for (column, organs) in scenes.iter().enumerate() {
        for (row, &(azimuth, elevation)) in views.iter().enumerate() {
            let mut camera = Camera::framing(lo, hi, azimuth, elevation);
            // The framing fits the whole box; the flower fills less of it.
            camera.fov_y_deg *= zoom;
            let picture = renderer.render(organs, &camera, tile, tile)?;
            sheet.copy_from(&picture, tile * column as u32, tile * row as u32)?;
        }
    }
    sheet.save(&out)?;
    println!("wrote {out}");
    result.map(|_| ()).map_err(Into::into)
}
