//! Issue 11 item 1 on every shipped flower: every kind of edit a user
//! makes after a run, sent through the simulation worker as the window
//! sends it (`Worker::start` with the edited project; the worker edits its
//! last run, `Simulation::edit`), must give every keyframe, bit for bit,
//! as a run of the edited project from the bud; and undoing it (the
//! original project again) the original run's keyframes. Each flower is
//! remeshed coarser than built (`SWEEP_EDGE`, default 1.7 times its
//! smallest template's mean edge) so the sweep is cheap, and run whole and
//! as a one-organ preview (organ 0).
//!
//! ```text
//! cargo run --release -p anthesis-garden --example rerun_sweep            # every flower
//! cargo run --release -p anthesis-garden --example rerun_sweep -- lily    # some
//! RAYON_NUM_THREADS=1 target/release/examples/rerun_sweep > one.txt
//! RAYON_NUM_THREADS=2 target/release/examples/rerun_sweep > two.txt
//! diff one.txt two.txt   # the digests must not depend on the threads
//! ```
//!
//! Per case it prints what the rule says (`edit_between`), the first
//! keyframe the worker computed, the first keyframe whose bits differ
//! between runs of the two projects from the bud (the rule must not start
//! later; where it starts earlier the line says by how much), whether the
//! edit and its undo matched the runs from the bud, and a digest of the
//! edited run's keyframes. It ends with the count of failures, and exits
//! non-zero when there is one.

use std::hash::{DefaultHasher, Hash, Hasher};
use std::sync::Arc;
use std::time::Duration;

use anthesis_bud::quality;
use anthesis_flower::resolution::resolve;
use anthesis_flower::{JointRamp, Project, Resolution};
use anthesis_garden::{builtin, builtin_names};
use anthesis_maps::brush::{Brush, PaintTarget, dab_keyed};
use anthesis_maps::{Blend, MapKind};
use anthesis_sim::fixtures::stroke_near_tip;
use anthesis_sim::resume::{Edit, edit_between};
use anthesis_sim::worker::{Event, Worker};
use anthesis_sim::{Selection, Simulation, run};
use glam::DVec2;

/// One edit: its name and the edited project.
type Case = (String, Project);

/// Every keyframe of a run of `project` from the bud (no checkpoints), and
/// the error it stopped on, if it did (a coarse flower edited hard may
/// not converge; the worker must then stop at the same keyframe, the same
/// way).
fn from_the_bud(project: &Project, selection: &Selection) -> (Vec<Vec<u64>>, Option<String>) {
    let mut keyframes = Vec::new();
    let error = run(project, selection, &mut |_, k| keyframes.push(k.bits()))
        .err()
        .map(|e| e.to_string());
    (keyframes, error)
}

/// What the worker sent for `run`: the first keyframe it computed, every
/// keyframe, and the error it stopped on, if it did.
type Sent = (u32, Vec<Vec<u64>>, Option<String>);

fn collect(worker: &Worker, run: u64) -> Result<Sent, String> {
    let mut first = None;
    let mut keyframes = Vec::new();
    loop {
        let event = worker
            .wait_event(Duration::from_secs(600))
            .ok_or("the worker did not answer")?;
        if event.run() != run {
            continue;
        }
        match event {
            Event::Started { first_computed, .. } => first = Some(first_computed),
            Event::Keyframe { keyframe, .. } => keyframes.push(keyframe.bits()),
            Event::Progress { .. }
            | Event::Proxy { .. }
            | Event::ProxyEnded { .. }
            | Event::Crossed { .. } => {}
            Event::Finished { .. } => {
                return Ok((first.ok_or("no Started event")?, keyframes, None));
            }
            Event::Failed { error, .. } => {
                let first = first.ok_or(format!("failed before it started: {error}"))?;
                return Ok((first, keyframes, Some(error.to_string())));
            }
            Event::Cancelled { .. } => return Err("cancelled".into()),
        }
    }
}

/// Keyframes of `run` until keyframe `index` arrives (then returns, the run
/// still going).
fn wait_for_keyframe(worker: &Worker, run: u64, index: u32) {
    loop {
        let event = worker
            .wait_event(Duration::from_secs(600))
            .expect("the worker answers");
        match event {
            Event::Keyframe { keyframe, run: r } if r == run && keyframe.index >= index => return,
            e if e.ends(run) => panic!("run {run} ended before keyframe {index}: {e:?}"),
            _ => {}
        }
    }
}

fn digest(keyframes: &[Vec<u64>]) -> u64 {
    let mut hasher = DefaultHasher::new();
    keyframes.hash(&mut hasher);
    hasher.finish()
}

/// The first keyframe whose bits differ between two runs (their length + 1
/// if none, the shorter's length if one is a prefix of the other).
fn first_difference(a: &[Vec<u64>], b: &[Vec<u64>]) -> usize {
    a.iter()
        .zip(b)
        .position(|(x, y)| x != y)
        .unwrap_or(if a.len() == b.len() {
            a.len()
        } else {
            a.len().min(b.len())
        })
}

/// The flower `name` remeshed coarse: at `SWEEP_EDGE` (default 1.7) times
/// its smallest template's mean edge, or less where a template would not
/// attach there (the five-petal's base holds 2 particles at 1.7).
fn coarse(name: &str) -> Project {
    let project = builtin(name).expect("listed").expect("loads");
    let smallest = project
        .flower
        .templates
        .iter()
        .map(|t| quality(&t.mesh).mean_edge)
        .fold(f64::INFINITY, f64::min);
    let factor: f64 = std::env::var("SWEEP_EDGE").map_or(1.7, |f| f.parse().expect("a factor"));
    let mut factor = factor;
    loop {
        let mut at = project.clone();
        at.settings.resolution = Resolution::MeanEdge(factor * smallest);
        match resolve(&at)
            .map_err(|e| e.to_string())
            .and_then(|resolved| {
                Simulation::new(&resolved, &Selection::All)
                    .map(|_| resolved)
                    .map_err(|e| e.to_string())
            }) {
            Ok(resolved) => {
                println!("   {name} at {factor:.2} times its smallest mean edge");
                return resolved;
            }
            Err(e) if factor > 1.0 => {
                println!("   {name} at {factor:.2} times its smallest mean edge: {e}");
                factor -= 0.1;
            }
            Err(e) => panic!("{name}: {e}"),
        }
    }
}

/// A stroke with the app's default brush on map `target` of key `key`
/// (the app's `dab_keyed`), along the midrib from v = 0.7 to 0.9.
fn paint(project: &mut Project, template: usize, key: usize, target: PaintTarget) {
    let maps = &mut project.flower.templates[template].maps;
    for i in 0..=8 {
        let v = 0.7 + 0.2 * f64::from(i) / 8.0;
        dab_keyed(
            maps,
            key,
            target,
            &Brush::default(),
            DVec2::new(0.5, v),
            DVec2::new(0.3, 1.0),
        );
    }
}

/// Every edit kind this flower allows, for a run of `selection`.
fn cases(base: &Project, selection: &Selection) -> Vec<Case> {
    let flower = &base.flower;
    let keyframes = base.settings.keyframes;
    let template = flower.organs[0].template;
    let keys = flower.templates[template].maps.keys().len();
    let mut out: Vec<Case> = Vec::new();
    let mut edit = |name: String, change: &dyn Fn(&mut Project)| {
        let mut after = base.clone();
        change(&mut after);
        out.push((name, after));
    };
    for key in 0..keys {
        edit(format!("stroke on key {key}"), &|p| {
            stroke_near_tip(p, template, key)
        });
    }
    // The other templates' late keys: in a preview of organ 0 they are not
    // simulated.
    for (t, other) in flower.templates.iter().enumerate() {
        if t != template {
            let last = other.maps.keys().len() - 1;
            edit(format!("stroke on template {t}'s key {last}"), &|p| {
                stroke_near_tip(p, t, last)
            });
        }
    }
    if keys >= 2 {
        for key in 1..keys {
            let step = flower.templates[template].maps.keys()[key].step;
            let next = flower.templates[template]
                .maps
                .keys()
                .get(key + 1)
                .map_or(keyframes, |k| k.step);
            let previous = flower.templates[template].maps.keys()[key - 1].step;
            // Later when there is room, else earlier.
            let to = if step + 5 < next {
                step + 5
            } else {
                previous.max(step - 5) + 1
            };
            edit(format!("key {key} moved {step} -> {to}"), &|p| {
                p.flower.templates[template].maps.keys_mut()[key].step = to;
            });
        }
        let last = keys - 1;
        edit(format!("key {last}'s own dg"), &|p| {
            let t = &mut p.flower.templates[template];
            let dg = t.maps.keys()[last].dg.unwrap_or(t.dg);
            t.maps.keys_mut()[last].dg = Some(0.7 * dg);
        });
    }
    let from = keyframes * 6 / 10;
    edit(format!("joint ramp from {from}"), &|p| {
        p.flower.templates[template].joint_schedule.push(JointRamp {
            from_step: from,
            to_step: from + keyframes / 5,
            angle_deg: 4.0,
        });
    });
    // The other maps a user paints, on the late key; a key added and one
    // removed; another blend.
    let last = keys - 1;
    for target in [
        PaintTarget::Direction,
        PaintTarget::Scalar(MapKind::Stretch),
        PaintTarget::Scalar(MapKind::Bend),
        PaintTarget::Scalar(MapKind::WGrowth),
    ] {
        edit(format!("{} stroke on key {last}", target.label()), &|p| {
            paint(p, template, last, target)
        });
    }
    let step = flower.templates[template].maps.keys()[last].step;
    if step + 10 < keyframes {
        edit(format!("a key added at {}", step + 10), &|p| {
            let maps = &mut p.flower.templates[template].maps;
            let mut key = maps.keys()[last].clone();
            key.step = step + 10;
            let index = maps.insert(key).expect("a free step");
            paint(p, template, index, PaintTarget::Scalar(MapKind::EGrowth));
        });
    }
    if keys >= 2 {
        edit(format!("key {last} removed"), &|p| {
            p.flower.templates[template]
                .maps
                .remove(last)
                .expect("not the last key");
        });
        edit("smooth blend".into(), &|p| {
            p.flower.templates[template].maps.blend = Blend::Smooth;
        });
    }
    edit("12 more keyframes".into(), &|p| p.settings.keyframes += 12);
    edit("15 fewer keyframes".into(), &|p| p.settings.keyframes -= 15);
    edit("template colour".into(), &|p| {
        p.flower.templates[template].colour = [0.9, 0.1, 0.5, 1.0];
    });
    if !flower.parts.is_empty() {
        edit("every part's colours".into(), &|p| {
            for part in &mut p.flower.parts {
                part.colour = [0.1, 0.9, 0.2, 1.0];
                part.head_colour = [0.9, 0.9, 0.1, 1.0];
            }
        });
    }
    if let Some(moving) = flower.parts.iter().position(|p| !p.schedule.is_empty()) {
        // Back towards the axis (the stamens of the built-ins then touch
        // nothing at this resolution), and out into the petals (the coarse
        // lily's run then stops at keyframe 79: the worker must stop there
        // too, and its undo go on from the last keyframe kept).
        for angle_deg in [-5.0, 5.0] {
            edit(
                format!("part {moving}'s later ramp by {angle_deg} from {from}"),
                &|p| {
                    p.flower.parts[moving].schedule.push(JointRamp {
                        from_step: from,
                        to_step: from + keyframes / 5,
                        angle_deg,
                    });
                },
            );
        }
    }
    if matches!(selection, Selection::Only(_)) && flower.organs.len() > 1 {
        let last = flower.organs.len() - 1;
        edit(format!("organ {last} turned (not simulated)"), &|p| {
            p.flower.organs[last].placement.azimuth_deg += 2.0;
        });
    }
    out
}

fn main() {
    let wanted: Vec<String> = std::env::args().skip(1).collect();
    let mut failures = 0;
    let mut cases_run = 0;
    let worker = Worker::spawn(|| {}).expect("the worker thread");
    for name in builtin_names() {
        if !wanted.is_empty() && !wanted.iter().any(|w| w == name) {
            continue;
        }
        let base = coarse(name);
        let particles: usize = (0..base.flower.organs.len())
            .map(|o| base.flower.template_of(o).mesh.vertex_count())
            .sum();
        println!(
            "== {name}: {particles} particles, {} keyframes",
            base.settings.keyframes
        );
        for selection in [Selection::All, Selection::Only(0)] {
            let organs = selection.organs(base.flower.organs.len());
            let original = from_the_bud(&base, &selection);
            if let Some(error) = &original.1 {
                println!("FAIL {name} {selection:?}: the original run stopped: {error}");
                failures += 1;
                continue;
            }
            let base = Arc::new(base.clone());
            let started = worker.start(Arc::clone(&base), selection.clone());
            let first_run = collect(&worker, started).expect("the original run");
            if (first_run.1.as_slice(), &first_run.2) != (original.0.as_slice(), &original.1) {
                println!("FAIL {name} {selection:?}: the worker's run differs from the bud's");
                failures += 1;
            }
            for (what, after) in cases(&base, &selection) {
                cases_run += 1;
                let rule = edit_between(&base, &after, &organs);
                let expected = match rule {
                    Edit::Nothing => original.0.len() as u32,
                    Edit::From(step) => step,
                    Edit::Everything => 1,
                };
                let reference = from_the_bud(&after, &selection);
                let differs = first_difference(&original.0, &reference.0);
                let after = Arc::new(after);
                let edited = collect(&worker, worker.start(Arc::clone(&after), selection.clone()));
                let undone = collect(&worker, worker.start(Arc::clone(&base), selection.clone()));
                let mut problems = Vec::new();
                let mut compare =
                    |what: &str,
                     sent: &Result<Sent, String>,
                     run: &(Vec<Vec<u64>>, Option<String>)| {
                        match sent {
                            Ok((_, keyframes, error)) => {
                                if *keyframes != run.0 {
                                    let at = first_difference(keyframes, &run.0);
                                    problems.push(format!("{what} run differs from keyframe {at}"));
                                }
                                if *error != run.1 {
                                    problems.push(format!(
                                        "{what} run stopped on {error:?}, from the bud on {:?}",
                                        run.1
                                    ));
                                }
                            }
                            Err(e) => problems.push(format!("{what} run: {e}")),
                        }
                    };
                compare("edited", &edited, &reference);
                compare("undone", &undone, &original);
                if let Ok((first, keyframes, _)) = &edited
                    && *first != expected.min(keyframes.len().max(1) as u32)
                {
                    problems.push(format!("started at {first}, not {expected}"));
                }
                // The rule may not keep a keyframe that differs.
                if (expected as usize) > differs {
                    problems.push(format!("keeps keyframe {differs}, which the edit changes"));
                }
                let slack = differs as i64 - i64::from(expected);
                let (first, undo_first) = (
                    edited.as_ref().map_or(0, |e| e.0),
                    undone.as_ref().map_or(0, |u| u.0),
                );
                let same_length = reference.0.len() == original.0.len();
                println!(
                    "{} {name} {selection:?} {what}: rule {rule:?}, computed from {first} (undo {undo_first}), bits differ from {}{}{}, digest {:016x}",
                    if problems.is_empty() { "ok  " } else { "FAIL" },
                    if differs == original.0.len() && same_length {
                        "none".to_string()
                    } else {
                        differs.to_string()
                    },
                    if slack > 0 && !(differs == original.0.len() && same_length) {
                        format!(" (starts {slack} early)")
                    } else if slack > 0 {
                        " (nothing changes)".to_string()
                    } else {
                        String::new()
                    },
                    reference
                        .1
                        .as_ref()
                        .map_or(String::new(), |e| format!(", stops: {e}")),
                    digest(&reference.0),
                );
                for p in &problems {
                    println!("     {p}");
                }
                failures += usize::from(!problems.is_empty());
            }
            // An edit while the run goes on, and its undo while that goes
            // on: each cancels the run inside a keyframe, and the next goes
            // on from the last kept keyframe.
            let template = base.flower.organs[0].template;
            let last_key = base.flower.templates[template].maps.keys().len() - 1;
            let mut painted = (*base).clone();
            stroke_near_tip(&mut painted, template, last_key);
            let painted = Arc::new(painted);
            let half = base.settings.keyframes / 2;
            let run1 = worker.start(Arc::clone(&base), selection.clone());
            wait_for_keyframe(&worker, run1, 5);
            let run2 = worker.start(Arc::clone(&painted), selection.clone());
            wait_for_keyframe(&worker, run2, half);
            let run3 = worker.start(Arc::clone(&base), selection.clone());
            let undone = collect(&worker, run3);
            let run4 = worker.start(Arc::clone(&painted), selection.clone());
            let redone = collect(&worker, run4);
            let reference = from_the_bud(&painted, &selection);
            cases_run += 1;
            let ok = undone
                .as_ref()
                .is_ok_and(|u| (&u.1, &u.2) == (&original.0, &original.1))
                && redone
                    .as_ref()
                    .is_ok_and(|r| (&r.1, &r.2) == (&reference.0, &reference.1));
            println!(
                "{} {name} {selection:?} stroke, undo and redo while running: undo from {:?}, redo from {:?}",
                if ok { "ok  " } else { "FAIL" },
                undone.as_ref().map(|u| u.0),
                redone.as_ref().map(|r| r.0),
            );
            failures += usize::from(!ok);
        }
    }
    println!("{cases_run} cases, {failures} failures");
    if failures > 0 {
        std::process::exit(1);
    }
}
