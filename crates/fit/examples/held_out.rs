//! The held-out benchmark of issue 36: targets the fit has never seen, of
//! other meshes. Each is an Eustoma petal grown from one cultivar's maps
//! (the cultivars share their bud) on a mesh remeshed at another edge than
//! the project's, and is fitted from another cultivar's project, its maps
//! as they are; the last is made scan-like (moved, turned, 0.2 % noise,
//! vertices shuffled, no UVs) and registered first. Each fitted project is
//! re-simulated at the project's own resolution and measured by surface
//! distance both ways. Prints the README's table: target, vertices, RMS,
//! max, seconds.
//!
//! `cargo run --release -p anthesis-fit --example held_out [-- --write DIR] [--only N]`:
//! with `--write DIR` the targets are also written as OBJ files
//! (`DIR/target-N.obj`) for `anthesis fit builtin:eustoma-… --organ
//! petal-1 --target DIR/target-N.obj [--register]`; `--only N` runs row N
//! (from 1) alone. For the scan it also prints how far the registration's
//! turn is from undoing the scan's (known) motion, and with
//! `HELD_OUT_TRUTH=1` in the environment how far the project's current
//! shape is from the scan placed by the registration and by the truth.

use std::fmt::Write as _;

use anthesis_fit::{
    FitSettings, Similarity, Surface, Target, fit, register_target, simulate_final,
};
use anthesis_flower::Project;
use anthesis_flower::resolution::{Resolution, resolve};
use anthesis_garden::Cultivar;
use glam::{DQuat, DVec3};

/// One held-out target.
struct Case {
    /// Grown from this cultivar's maps.
    grown: Cultivar,
    /// At the project's mean edge times this.
    edge: f64,
    /// Fitted from this cultivar's project.
    fitted_from: Cultivar,
    /// Made scan-like and registered.
    scan: bool,
}

const CASES: [Case; 4] = [
    Case {
        grown: Cultivar::MaiteLady,
        edge: 0.5,
        fitted_from: Cultivar::MellowYellow,
        scan: false,
    },
    Case {
        grown: Cultivar::Pinocchio,
        edge: 0.75,
        fitted_from: Cultivar::MaiteLady,
        scan: false,
    },
    Case {
        grown: Cultivar::MellowYellow,
        edge: 1.3,
        fitted_from: Cultivar::Pinocchio,
        scan: false,
    },
    Case {
        grown: Cultivar::Pinocchio,
        edge: 0.7,
        fitted_from: Cultivar::MellowYellow,
        scan: true,
    },
];

fn builtin(cultivar: Cultivar) -> Result<Project, Box<dyn std::error::Error>> {
    Ok(anthesis_garden::builtin(cultivar.folder_name()).ok_or("the Eustoma is not built in")??)
}

fn mean_edge(project: &Project) -> f64 {
    let mesh = &project.flower.template_of(0).mesh;
    let (sum, count) = mesh.triangles.iter().fold((0.0, 0), |(s, c), t| {
        let [a, b, c3] = t.map(|v| mesh.positions[v as usize]);
        (s + a.distance(b) + b.distance(c3) + c3.distance(a), c + 3)
    });
    sum / f64::from(count)
}

/// A small deterministic generator (no test data depends on a crate's
/// random stream changing between versions).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// A standard normal sample (Box–Muller).
    fn normal(&mut self) -> f64 {
        let (a, b) = (self.next(), self.next());
        (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
    }
}

/// `target` made scan-like: every vertex moved by 0.2 % of `length` of
/// noise (each coordinate normal with that deviation / √3), the vertices
/// shuffled, the UVs dropped, and the whole turned and moved away.
/// The motion a scan is given: turned 2.3 rad (132°) about (0.4, −1, 0.7)
/// and moved far from the flower.
fn scan_motion() -> Similarity {
    Similarity {
        rotation: DQuat::from_axis_angle(DVec3::new(0.4, -1.0, 0.7).normalize(), 2.3),
        scale: 1.0,
        translation: DVec3::new(120.0, -35.0, 60.0),
    }
}

fn scan_of(target: &Target, length: f64, seed: u64) -> Target {
    let mut random = Lcg(seed);
    let n = target.vertex_count();
    let mut order: Vec<usize> = (0..n).collect();
    for i in (1..n).rev() {
        let j = ((random.next() * (i + 1) as f64) as usize).min(i);
        order.swap(i, j);
    }
    let mut new_index = vec![0u32; n];
    for (new, &old) in order.iter().enumerate() {
        new_index[old] = new as u32;
    }
    let motion = scan_motion();
    let sigma = 0.002 * length / 3f64.sqrt();
    let positions = order
        .iter()
        .map(|&old| {
            let noise = DVec3::new(random.normal(), random.normal(), random.normal()) * sigma;
            motion.apply(target.surface.positions[old] + noise)
        })
        .collect();
    let triangles = target
        .surface
        .triangles
        .iter()
        .map(|t| t.map(|v| new_index[v as usize]))
        .collect();
    Target {
        surface: Surface::new(positions, triangles),
        uvs: None,
        warnings: Vec::new(),
    }
}

fn obj(target: &Target) -> String {
    let mut text = String::from("o petal-1\n");
    for p in &target.surface.positions {
        let _ = writeln!(text, "v {} {} {}", p.x, p.y, p.z);
    }
    if let Some(uvs) = &target.uvs {
        for uv in uvs {
            let _ = writeln!(text, "vt {} {}", uv.x, uv.y);
        }
    }
    for t in &target.surface.triangles {
        let [a, b, c] = t.map(|v| v + 1);
        if target.uvs.is_some() {
            let _ = writeln!(text, "f {a}/{a} {b}/{b} {c}/{c}");
        } else {
            let _ = writeln!(text, "f {a} {b} {c}");
        }
    }
    text
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1).cloned())
    };
    let write = value("--write").map(std::path::PathBuf::from);
    let only: Option<usize> = value("--only").map(|s| s.parse()).transpose()?;
    if let Some(dir) = &write {
        std::fs::create_dir_all(dir)?;
    }
    let settings = FitSettings::default();
    let mut table = String::from(
        "| target | vertices | fitted from | RMS | max | seconds | stopped |\n|---|---|---|---|---|---|---|\n",
    );
    for (row, case) in CASES.iter().enumerate() {
        if only.is_some_and(|o| o != row + 1) {
            continue;
        }
        // The target: the grown cultivar's petal at another edge.
        let grown = builtin(case.grown)?;
        let mut fine = grown.clone();
        fine.settings.resolution = Resolution::MeanEdge(case.edge * mean_edge(&resolve(&grown)?));
        let fine = resolve(&fine)?;
        let organ = 0;
        let template = fine.flower.template_of(organ);
        let shape = simulate_final(&fine, organ, template.maps.clone(), &|| false)?;
        let mut target = Target {
            surface: Surface::new(shape, template.mesh.triangles.clone()),
            uvs: Some(template.mesh.uvs.clone()),
            warnings: Vec::new(),
        };
        // The project it is fitted from, at its own resolution.
        let project = resolve(&builtin(case.fitted_from)?)?;
        let organ_name = project.flower.organs[organ].name.clone();
        let length0 = anthesis_fit::organ_length(&project, organ, &target, Similarity::IDENTITY)?;
        let mut placement = Similarity::IDENTITY;
        let mut fit_settings = settings.clone();
        let started = std::time::Instant::now();
        if case.scan {
            target = scan_of(&target, length0, 36 + row as u64);
            let registered = register_target(&project, organ, &target, false, &|| false)?;
            eprintln!("  {}", registered.describe());
            placement = registered.registration.placement;
            // How far from undoing the scan's motion (the truth is known
            // here): the turn left over.
            let left = placement.rotation * scan_motion().rotation;
            eprintln!(
                "  registration: {:.2}° from undoing the scan's turn",
                left.to_axis_angle().1.to_degrees()
            );
            if std::env::var_os("HELD_OUT_TRUTH").is_some() {
                let m = scan_motion();
                let truth = Similarity {
                    rotation: m.rotation.inverse(),
                    scale: 1.0,
                    translation: -(m.rotation.inverse() * m.translation),
                };
                let template = project.flower.template_of(organ);
                let current = simulate_final(&project, organ, template.maps.clone(), &|| false)?;
                for (name, at) in [("truth", truth), ("found", placement)] {
                    let (rms, max) = anthesis_fit::distances(
                        &current,
                        &template.mesh.triangles,
                        &target,
                        at,
                        registered.length,
                    );
                    eprintln!(
                        "  {name}: RMS {:.2} %, max {:.2} % from the current shape",
                        100.0 * rms,
                        100.0 * max
                    );
                }
            }
            fit_settings.refine_placement = true;
        }
        if let Some(dir) = &write {
            std::fs::write(dir.join(format!("target-{}.obj", row + 1)), obj(&target))?;
        }
        let name = format!(
            "{} petal at {}× the edge{}",
            case.grown.project_name(),
            case.edge,
            if case.scan {
                ", scan-like (moved, turned, 0.2 % noise, shuffled, no UVs), --register"
            } else {
                ""
            }
        );
        eprintln!(
            "{name} ({} vertices), fitted from {}",
            target.vertex_count(),
            case.fitted_from.project_name()
        );
        let result = fit(
            &project,
            organ,
            &target,
            placement,
            &fit_settings,
            &mut |p| {
                eprintln!(
                    "  iteration {}: RMS {:.3} %, max {:.3} %, {} simulations, {:.1} s",
                    p.iteration,
                    100.0 * p.rms,
                    100.0 * p.max,
                    p.simulations,
                    p.seconds
                )
            },
            &|| false,
        )?;
        let seconds = started.elapsed().as_secs_f64();
        if case.scan {
            let left = result.placement.rotation * scan_motion().rotation;
            eprintln!(
                "  after the fit: {:.2}° from undoing the scan's turn",
                left.to_axis_angle().1.to_degrees()
            );
        }
        // Re-simulated at the project's own resolution, as a saved
        // project runs (the maps are those a 16-bit PNG holds).
        let again = simulate_final(&project, organ, result.maps.clone(), &|| false)?;
        let (rms, max) = anthesis_fit::distances(
            &again,
            &project.flower.template_of(organ).mesh.triangles,
            &target,
            result.placement,
            result.length,
        );
        println!(
            "{name}: {} vertices against {organ_name}'s {}, RMS {:.2} %, max {:.2} %, {:.1} s ({}), {}",
            target.vertex_count(),
            project.flower.template_of(organ).mesh.vertex_count(),
            100.0 * rms,
            100.0 * max,
            seconds,
            result.stop.name(),
            result.verdict()
        );
        let _ = writeln!(
            table,
            "| {name} | {} | {} | {:.2} % | {:.2} % | {:.1} | {} |",
            target.vertex_count(),
            case.fitted_from.project_name(),
            100.0 * rms,
            100.0 * max,
            seconds,
            result.stop.name()
        );
    }
    println!("\n{table}");
    Ok(())
}
