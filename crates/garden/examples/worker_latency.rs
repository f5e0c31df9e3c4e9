//! What the worker takes, without a window, for the strokes the window's
//! latency script paints (`app/tests/xvfb-edit-latency.sh`): the built-in
//! lily run once, then strokes on the petals' late key while keyframe 54
//! is viewed (or, with `early`, on the early key while keyframe 100 is),
//! each run with its proxy, as the window does. Prints, per stroke, the
//! milliseconds from the start to the proxy's and the converged keyframes
//! 54 and 100, the converged keyframe 40 (the first the late key changes)
//! and the run's end.
//!
//! ```text
//! cargo run --release -p anthesis-garden --example worker_latency [STROKES] [early]
//! ```
use std::sync::Arc;
use std::time::{Duration, Instant};

use anthesis_sim::Selection;
use anthesis_sim::fixtures::stroke_near_tip;
use anthesis_sim::worker::{Event, Worker};

fn main() {
    let strokes: usize = std::env::args()
        .nth(1)
        .map_or(5, |n| n.parse().expect("a number of strokes"));
    let project = anthesis_garden::builtin_lily().expect("the built-in lily");
    let proxy = anthesis_flower::resolution::proxy(&project).expect("the lily has a proxy");
    let early = std::env::args().nth(2).is_some_and(|a| a == "early");
    let worker = Worker::spawn(|| {}).expect("a worker thread");
    worker.set_viewed_keyframe(Some(if early { 100 } else { 54 }));
    let template = project.flower.organs[0].template;
    let key = if early {
        0
    } else {
        project.flower.templates[template].maps.keys().len() - 1
    };
    worker.start_with_proxy(
        Arc::new(project.clone()),
        Some(Arc::new(proxy.clone())),
        Selection::All,
    );
    wait_for_end(&worker, Instant::now());
    let mut current = project;
    for stroke in 1..=strokes {
        let mut painted = current.clone();
        stroke_near_tip(&mut painted, template, key);
        // The window's proxy: the proxy meshes with the painted maps.
        let mut painted_proxy = proxy.clone();
        for (coarse, fine) in painted_proxy
            .flower
            .templates
            .iter_mut()
            .zip(&painted.flower.templates)
        {
            coarse.maps = fine.maps.clone();
        }
        let started = Instant::now();
        worker.start_with_proxy(
            Arc::new(painted.clone()),
            Some(Arc::new(painted_proxy)),
            Selection::All,
        );
        println!("stroke {stroke}: {}", wait_for_end(&worker, started));
        current = painted;
    }
}

/// Waits for the run's end; the times of its landmarks since `started`.
fn wait_for_end(worker: &Worker, started: Instant) -> String {
    let ms = || started.elapsed().as_secs_f64() * 1e3;
    let mut line = String::new();
    loop {
        match worker.wait_event(Duration::from_secs(300)) {
            Some(Event::Proxy { keyframe, .. }) if [54, 100].contains(&keyframe.index) => {
                line += &format!("proxy {} at {:.0} ms, ", keyframe.index, ms());
            }
            Some(Event::Keyframe { keyframe, .. }) if [40, 54, 100].contains(&keyframe.index) => {
                line += &format!("converged {} at {:.0} ms, ", keyframe.index, ms());
            }
            Some(Event::Finished { .. }) => return line + &format!("end at {:.0} ms", ms()),
            Some(Event::Failed { error, .. }) => panic!("the run failed: {error}"),
            Some(_) => {}
            None => panic!("no event for five minutes"),
        }
    }
}
