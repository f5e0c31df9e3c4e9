//! `anthesis measure`: a run's measurements as a table (issue 41 item 3),
//! one CSV row per keyframe and organ: surface area, mean and Gaussian
//! curvature (median and area-weighted mean over the interior), the mean
//! principal stretches against the bud, the midrib's and the margin's
//! length and the contact area (`anthesis_sim::measure` says how each is
//! computed). Lengths in millimetres when the project states its unit,
//! else in the project's units; each column's unit is in its header.

use std::fmt::Write as _;
use std::path::PathBuf;

use anthesis_flower::Resolution;
use anthesis_sim::batch;
use anthesis_sim::measure::{
    OrganLayout, QUANTITIES, Surface, default_contact_distance, measure_keyframe, real_scale,
};
use anthesis_sim::memory::KeyframeCost;
use anthesis_sim::{Keyframe, Selection};
use anyhow::{Result, bail};
use clap::Args;

use super::simulate::{run_with_progress, set_keyframes};
use super::stream::{out, say};
use super::{check_count, check_particle_limit, load, parse_edge, warn_about_the_cache};

/// `anthesis measure PROJECT --out table.csv`.
#[derive(Debug, Args)]
pub struct MeasureArgs {
    /// A project file (*.anthesis.toml), its folder, or builtin:NAME.
    pub project: PathBuf,
    /// Write the table here (CSV); without it, to standard output.
    #[arg(long, value_name = "TABLE.csv")]
    pub out: Option<PathBuf>,
    /// Rows only for these organs (names, comma-separated; default: all).
    /// The whole flower is simulated either way, so contacts count.
    #[arg(long, value_name = "NAME,…", value_delimiter = ',')]
    pub organs: Vec<String>,
    /// Simulate only this organ, alone (the single-organ preview: no
    /// collisions with other organs; it may still touch the parts).
    #[arg(long, value_name = "NAME", conflicts_with = "organs")]
    pub alone: Option<String>,
    /// Number of keyframes simulated, 1 to 10,000 (default: the project's).
    #[arg(long)]
    pub keyframes: Option<i64>,
    /// Rows only for these keyframes: numbers and ranges FIRST:LAST or
    /// FIRST:LAST:STEP, comma-separated (`0,50,100`, `0:100:10`; default:
    /// the bud and every keyframe).
    #[arg(long, value_name = "LIST")]
    pub at: Option<String>,
    /// Simulate at this mean edge length (see `simulate --edge`).
    #[arg(long, value_name = "LENGTH|as-built", value_parser = parse_edge)]
    pub edge: Option<Resolution>,
    /// A vertex touches another organ or a part when it lies within this
    /// distance of its surface, in project units (default: twice the
    /// project's collision offset).
    #[arg(long, value_name = "LENGTH")]
    pub contact_distance: Option<f64>,
    /// Go on past a keyframe whose triangles cross, with a warning.
    #[arg(long)]
    pub allow_crossings: bool,
}

/// The keyframes `list` names (`0,5,10:20:5`), each at most `last`.
fn keyframes_in(list: &str, last: u32) -> Result<Vec<u32>> {
    let number = |text: &str| -> Result<u32> {
        let n: u32 = text
            .trim()
            .parse()
            .map_err(|_| anyhow::anyhow!("--at: `{text}` is not a keyframe number"))?;
        if n > last {
            bail!("--at: keyframe {n} is past the run's last keyframe, {last}");
        }
        Ok(n)
    };
    let mut out = Vec::new();
    for item in list.split(',') {
        let parts: Vec<&str> = item.split(':').collect();
        match parts.as_slice() {
            [one] => out.push(number(one)?),
            [first, end] | [first, end, _] => {
                let (first, end) = (number(first)?, number(end)?);
                let step = match parts.get(2) {
                    Some(step) => match step.trim().parse::<u32>() {
                        Ok(s) if s > 0 => s,
                        _ => bail!("--at: the step in `{item}` must be a whole number above 0"),
                    },
                    None => 1,
                };
                if first > end {
                    bail!("--at: `{item}` runs backwards");
                }
                out.extend((first..=end).step_by(step as usize));
            }
            _ => bail!("--at: `{item}` is not a keyframe or FIRST:LAST[:STEP]"),
        }
    }
    out.sort_unstable();
    out.dedup();
    Ok(out)
}

pub(super) fn measure(args: &MeasureArgs) -> Result<()> {
    let mut project = load(&args.project)?;
    let keyframes = args
        .keyframes
        .map(|n| check_count("--keyframes", n, 1, anthesis_flower::MAX_KEYFRAMES as usize))
        .transpose()?
        .map(|n| n as u32);
    set_keyframes(&mut project, keyframes)?;
    if let Some(edge) = args.edge {
        project.settings.resolution = edge;
    }
    let selection = super::selection(&project, args.alone.as_deref())?;
    for name in &args.organs {
        // Named in the message with the organs there are.
        super::selection(&project, Some(name))?;
    }
    let chosen = match &args.at {
        Some(list) => keyframes_in(list, project.settings.keyframes)?,
        None => (0..=project.settings.keyframes).collect(),
    };
    let contact_distance = match args.contact_distance {
        Some(d) if d >= 0.0 && d.is_finite() => d,
        Some(d) => bail!("--contact-distance must be 0 or more (and finite), got {d}"),
        None => default_contact_distance(project.settings.collision_offset),
    };
    if let Some(out) = &args.out {
        anthesis_files::check_destination(out)?;
    }
    check_particle_limit(&project, args.edge.is_some())?;
    let prepared = batch::prepare(&project, &selection, KeyframeCost::Kept, None);
    warn_about_the_cache();
    let project = prepared?;

    let (run, run_result) = run_with_progress(&project, &selection, args.allow_crossings)?;

    let table = table(
        &project,
        &selection,
        &run.keyframes,
        &chosen,
        &args.organs,
        contact_distance,
    );
    match &args.out {
        Some(path) => {
            anthesis_files::write_atomic(path, table.as_bytes())?;
            say!(
                "wrote {} ({} rows)",
                path.display(),
                table.lines().count() - 1
            );
        }
        None => out!("{}", table.trim_end())?,
    }
    match run_result {
        Ok(_) => Ok(()),
        Err(failure) => Err(failure.context(format!(
            "the table holds the keyframes before it (0 to {})",
            run.stepped.done
        ))),
    }
}

/// The CSV table of `keyframes` (the bud first) at the `chosen` keyframes
/// that were computed, for the `organs` named (all when none).
fn table(
    project: &anthesis_flower::Project,
    selection: &Selection,
    keyframes: &[Keyframe],
    chosen: &[u32],
    organs: &[String],
    contact_distance: f64,
) -> String {
    let flower = &project.flower;
    let simulated = selection.organs(flower.organs.len());
    let template_layouts: Vec<OrganLayout> = flower
        .templates
        .iter()
        .map(|t| OrganLayout::new(&t.mesh))
        .collect();
    let layouts: Vec<OrganLayout> = simulated
        .iter()
        .map(|&i| template_layouts[flower.organs[i].template].clone())
        .collect();
    let (scale, unit) = real_scale(flower.unit);
    // The parts (receptacle, stamens, pistils, stem) organs may touch.
    let pieces = anthesis_flower::parts::part_pieces(flower);
    let mut text = String::from("keyframe,organ,template");
    for q in &QUANTITIES {
        let _ = write!(text, ",{} [{}]", q.name, q.unit(unit));
    }
    text.push('\n');
    let Some(bud) = keyframes.first() else {
        return text;
    };
    for &k in chosen {
        let Some(keyframe) = keyframes.get(k as usize) else {
            continue;
        };
        let at: Vec<Vec<glam::DVec3>> = pieces.iter().map(|p| p.positions_at(k)).collect();
        let parts: Vec<Surface<'_>> = pieces
            .iter()
            .zip(&at)
            .map(|(p, x)| (x.as_slice(), p.mesh.triangles.as_slice()))
            .collect();
        let measures = measure_keyframe(
            &layouts,
            &bud.positions_in_world,
            &keyframe.positions_in_world,
            &parts,
            contact_distance,
        );
        for (&i, m) in simulated.iter().zip(&measures) {
            let organ = &flower.organs[i];
            if !organs.is_empty() && !organs.contains(&organ.name) {
                continue;
            }
            let _ = write!(
                text,
                "{k},{},{}",
                csv_field(&organ.name),
                csv_field(&flower.templates[organ.template].name)
            );
            for q in &QUANTITIES {
                let _ = write!(text, ",{}", q.value(&m.summary, scale));
            }
            text.push('\n');
        }
    }
    text
}

/// `text` as one CSV field: quoted, its quotes doubled, when it holds a
/// comma, a quote or a line break.
fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::keyframes_in;

    #[test]
    fn keyframe_lists_read_numbers_and_ranges() {
        assert_eq!(keyframes_in("0,50,100", 100).unwrap(), vec![0, 50, 100]);
        assert_eq!(keyframes_in("0:20:10,5", 100).unwrap(), vec![0, 5, 10, 20]);
        assert_eq!(keyframes_in("3:5", 10).unwrap(), vec![3, 4, 5]);
        assert!(keyframes_in("11", 10).is_err());
        assert!(keyframes_in("5:3", 10).is_err());
        assert!(keyframes_in("0:4:0", 10).is_err());
        assert!(keyframes_in("x", 10).is_err());
    }
}
