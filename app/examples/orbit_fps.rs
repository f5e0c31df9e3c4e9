//! Frames per second of the real desktop window while the camera orbits
//! the whole default lily (every organ, in its bud placement: recorded
//! session, no keyframes, so the solver takes no CPU). The camera turns
//! 3° per frame; after a 3 s warm-up, frames are timed for 20 s, then the
//! window closes and the frame rate is printed (median and mean).
//!
//! Run it under Xvfb with software Vulkan (no GPU needed):
//!
//! ```text
//! unset WGPU_BACKEND
//! xvfb-run -a -s "-screen 0 1600x1000x24" \
//!     cargo run --release -p anthesis-app --example orbit_fps
//! ```
//!
//! Vsync is off, so the number is what the machine can draw, not the
//! display's rate.

use std::time::{Duration, Instant};

use anthesis_app::desktop::{AnthesisApp, Startup, default_project};
use anyhow::{Result, anyhow};
use eframe::egui;

const WARM_UP: Duration = Duration::from_secs(3);
const MEASURED: Duration = Duration::from_secs(20);

/// The app, with the camera turned before every frame and the frames timed.
struct Orbiting {
    app: AnthesisApp,
    started: Instant,
    previous_frame: Option<Instant>,
    frame_seconds: Vec<f64>,
    reported: bool,
}

impl eframe::App for Orbiting {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        self.app
            .camera_mut()
            .orbit(glam::DVec2::new(3.0 / 0.4, 0.0));
        eframe::App::ui(&mut self.app, ui, frame);
        let now = Instant::now();
        if now - self.started > WARM_UP
            && let Some(previous) = self.previous_frame
        {
            self.frame_seconds.push((now - previous).as_secs_f64());
        }
        self.previous_frame = Some(now);
        if now - self.started > WARM_UP + MEASURED && !self.reported {
            self.reported = true;
            report(&self.frame_seconds, self.app.scene_rebuilds());
            ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close);
        }
        ui.ctx().request_repaint();
    }
}

fn report(frame_seconds: &[f64], scene_rebuilds: u64) {
    let mut sorted = frame_seconds.to_vec();
    sorted.sort_by(f64::total_cmp);
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(f64::NAN);
    let total: f64 = sorted.iter().sum();
    println!(
        "orbit_fps: {} frames in {total:.1} s: median {:.1} fps ({:.1} ms/frame), mean {:.1} fps; \
         scene rebuilds since start: {scene_rebuilds}",
        sorted.len(),
        1.0 / median,
        1e3 * median,
        sorted.len() as f64 / total,
    );
}

fn main() -> Result<()> {
    let project = default_project()?;
    let mut options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("Anthesis orbit fps")
            .with_inner_size([1400.0, 900.0]),
        renderer: eframe::Renderer::Wgpu,
        ..Default::default()
    };
    options.wgpu_options.surface.present_mode = eframe::wgpu::PresentMode::AutoNoVsync;
    eframe::run_native(
        "Anthesis orbit fps",
        options,
        Box::new(move |cc| {
            let startup = Startup {
                project: Some((project, None)),
                live: false,
                restore: false,
                warnings: Vec::new(),
            };
            let app = AnthesisApp::new(cc, startup).map_err(|e| e.to_string())?;
            Ok(Box::new(Orbiting {
                app,
                started: Instant::now(),
                previous_frame: None,
                frame_seconds: Vec::new(),
                reported: false,
            }))
        }),
    )
    .map_err(|e| anyhow!("cannot open the window: {e}"))
}
