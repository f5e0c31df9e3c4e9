//! The opening timeline: playback state (a time in keyframes that plays,
//! loops and is scrubbed) and its panel — scrubber with computed, stale
//! (an earlier run's, shown until the new run reaches them) and pending
//! keyframes and the time keys, transport buttons, progress, and a small
//! plot of energy and iterations per keyframe.

use eframe::egui::{self, Color32, Pos2, Rect, Sense, Stroke, StrokeKind, Vec2};

use super::command::Command;
use super::session::{FrameState, RunStatus, SimSession};

/// Keyframes per second at speed 1 (the glTF export's default frame rate).
pub const BASE_KEYFRAMES_PER_SECOND: f64 = 24.0;

/// Speeds offered in the speed menu.
pub const SPEEDS: [f64; 6] = [0.25, 0.5, 1.0, 2.0, 4.0, 8.0];

/// The longest frame playback advances by in full: keyframes go on in
/// real time down to four frames per second (skipping the keyframes not
/// drawn); a slower frame advances as if it were this long, so playback
/// slows down rather than jumping by seconds, and the timeline says so.
pub const MAX_FRAME_SECONDS: f64 = 0.25;

/// How long the keyframe rate playback reached is averaged over, in
/// seconds (an exponential average).
const RATE_SECONDS: f64 = 1.0;

/// Playback state.
#[derive(Debug, Clone, PartialEq)]
pub struct Playback {
    /// Where playback is, counted in keyframes: 0 is the bud, 2.5 halfway
    /// between keyframes 2 and 3 (shown interpolated).
    pub time_in_keyframes: f64,
    pub playing: bool,
    pub looping: bool,
    pub speed: f64,
    /// Show the newest keyframe as it arrives (on until the user scrubs,
    /// steps or plays).
    pub follow: bool,
    /// The keyframes per second of wall time playback reached lately
    /// (while playing and not waiting for the simulation), as
    /// exponentially decayed sums: keyframes, seconds.
    pub(super) reached: (f64, f64),
}

impl Default for Playback {
    fn default() -> Self {
        Playback {
            time_in_keyframes: 0.0,
            playing: false,
            looping: true,
            speed: 1.0,
            follow: true,
            reached: (0.0, 0.0),
        }
    }
}

impl Playback {
    /// Advances by `seconds` of wall time (the time since the last frame;
    /// at most [`MAX_FRAME_SECONDS`] count). `computed` is the newest
    /// keyframe available and `total` the last keyframe of the run.
    /// Playing stops at the newest computed keyframe and waits there;
    /// with loop on, a finished run starts again from the bud.
    ///
    /// Paused and not following, the playhead stays where the user put it
    /// even past the keyframes shown (a new run, or another selection's,
    /// has not reached it yet: the view shows the newest until it does).
    pub fn advance(&mut self, seconds: f64, computed: Option<u32>, total: u32) {
        if !self.playing && !self.follow {
            let end = computed.map_or(0.0, f64::from).max(f64::from(total));
            self.time_in_keyframes = self.time_in_keyframes.clamp(0.0, end);
            return;
        }
        let Some(computed) = computed else {
            self.time_in_keyframes = 0.0;
            self.reached = (0.0, 0.0);
            return;
        };
        let end = f64::from(computed);
        if self.follow {
            self.time_in_keyframes = end;
            self.reached = (0.0, 0.0);
            return;
        }
        if self.playing {
            let seconds = seconds.max(0.0);
            let step = seconds.min(MAX_FRAME_SECONDS) * self.speed * BASE_KEYFRAMES_PER_SECOND;
            self.time_in_keyframes += step;
            let mut waiting = false;
            if self.time_in_keyframes >= end {
                if self.looping && computed >= total && total > 0 {
                    self.time_in_keyframes %= end.max(1.0);
                } else {
                    self.time_in_keyframes = end;
                    waiting = true;
                    if computed >= total {
                        self.playing = false;
                    }
                }
            }
            if !waiting {
                let decay = (-seconds / RATE_SECONDS).exp();
                self.reached = (
                    self.reached.0 * decay + step,
                    self.reached.1 * decay + seconds,
                );
            }
        } else {
            self.reached = (0.0, 0.0);
        }
        self.time_in_keyframes = self.time_in_keyframes.clamp(0.0, end);
    }

    /// The keyframe rate playing reached over about the last second, in
    /// keyframes per second of wall time; `None` when not playing or not
    /// measured yet (under half a second played).
    pub fn reached_keyframes_per_second(&self) -> Option<f64> {
        let (keyframes, seconds) = self.reached;
        (self.playing && seconds >= 0.5 * RATE_SECONDS).then(|| keyframes / seconds)
    }

    /// The keyframe rate the speed asks for.
    pub fn wanted_keyframes_per_second(&self) -> f64 {
        self.speed * BASE_KEYFRAMES_PER_SECOND
    }

    pub fn toggle_play(&mut self, computed: Option<u32>) {
        self.follow = false;
        self.playing = !self.playing;
        // Play from the start when at the end.
        if self.playing && computed.is_some_and(|c| self.time_in_keyframes >= f64::from(c)) {
            self.time_in_keyframes = 0.0;
        }
    }

    /// Moves to the previous (`-1`) or next (`+1`) whole keyframe.
    pub fn step(&mut self, direction: i32, computed: Option<u32>) {
        self.follow = false;
        self.playing = false;
        let end = f64::from(computed.unwrap_or(0));
        let next = if direction < 0 {
            (self.time_in_keyframes - 1e-9).ceil() - 1.0
        } else {
            (self.time_in_keyframes + 1e-9).floor() + 1.0
        };
        self.time_in_keyframes = next.clamp(0.0, end);
    }

    pub fn go_to_start(&mut self) {
        self.follow = false;
        self.time_in_keyframes = 0.0;
    }

    /// To the newest keyframe, and follow new ones.
    pub fn go_to_end(&mut self, computed: Option<u32>) {
        self.playing = false;
        self.follow = true;
        self.time_in_keyframes = f64::from(computed.unwrap_or(0));
    }

    /// Jumps to `time` (clamped to the computed keyframes).
    pub fn scrub_to(&mut self, time: f64, computed: Option<u32>) {
        self.follow = false;
        self.playing = false;
        self.time_in_keyframes = time.clamp(0.0, f64::from(computed.unwrap_or(0)));
    }
}

/// Human-readable seconds: `0.3 s`, `42 s`, `3 min 5 s`.
pub fn format_seconds(seconds: f64) -> String {
    if !seconds.is_finite() {
        "an unknown time".to_string()
    } else if seconds < 0.05 {
        "under 0.1 s".to_string()
    } else if seconds < 9.95 {
        // A run of the default flowers takes about a second, an edit's
        // rerun less: whole seconds said "0 s" for both.
        format!("{seconds:.1} s")
    } else if seconds < 59.5 {
        format!("{seconds:.0} s")
    } else {
        // Rounded before splitting, so 119.7 s is 2 min 0 s, not 1 min 60 s.
        let whole = seconds.round() as u64;
        format!("{} min {} s", whole / 60, whole % 60)
    }
}

/// One line on the state of the run.
pub fn status_line(session: &SimSession) -> String {
    let done = session.last_index().unwrap_or(0);
    let total = session.total();
    match session.status() {
        RunStatus::Idle => "not simulated".to_string(),
        RunStatus::Queued => "starting…".to_string(),
        RunStatus::Running if session.proxy_running() => {
            let mut line = "quick preview (proxy) first".to_string();
            if let Some((keyframe, _)) = session.iteration() {
                line += &format!(", keyframe {keyframe}/{total}");
            }
            line + ", then full resolution"
        }
        RunStatus::Running => {
            let mut line = format!("simulating keyframe {}/{total}", (done + 1).min(total));
            if let Some(elapsed) = session.elapsed() {
                line += &format!(" · {} elapsed", format_seconds(elapsed.as_secs_f64()));
            }
            if let Some(left) = session.seconds_left() {
                line += &format!(" · about {} left", format_seconds(left));
            }
            line
        }
        RunStatus::Finished {
            seconds,
            first_computed,
        } if *first_computed > 1 => format!(
            "keyframes {first_computed}–{total} in {} ({} kept: the edit cannot change them)",
            format_seconds(*seconds),
            first_computed - 1
        ),
        RunStatus::Finished { seconds, .. } => {
            format!("{total} keyframes in {}", format_seconds(*seconds))
        }
        RunStatus::Failed { message } => format!("stopped at keyframe {done}: {message}"),
    }
}

/// The time keys marked on the timeline: the steps of the selected
/// template's keys (a step is a keyframe) and which one is painted.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct KeyMarks {
    /// Whose keys they are (a template's name), for the tooltip.
    pub template: String,
    pub steps: Vec<u32>,
    /// Index into `steps` of the key being painted.
    pub painted: Option<usize>,
}

/// What the status says about a view at `time` that is not the current
/// run's converged result (a proxy or an earlier run's): `None` when it
/// is.
pub fn stale_line(session: &SimSession, time: f64) -> Option<String> {
    let viewed = time.max(0.0).ceil();
    match session.state_at(time)? {
        FrameState::Converged => None,
        FrameState::Proxy => Some(format!(
            "proxy: coarse preview until the full-resolution run reaches {viewed:.0}"
        )),
        FrameState::Stale => Some(format!(
            "stale: previous result until the run reaches {viewed:.0}"
        )),
    }
}

/// The badge the viewport shows over a view that is not the current run's
/// converged result, and its colour.
pub fn viewport_badge(session: &SimSession, time: f64) -> Option<(&'static str, Color32)> {
    match session.state_at(time)? {
        FrameState::Converged => None,
        FrameState::Proxy => Some(("PROXY", PROXY_COLOUR)),
        FrameState::Stale => Some(("STALE", STALE_COLOUR)),
    }
}

/// The viewport's warning at `time`, under its state badge: which organs
/// cross in the converged keyframe shown, if any.
pub fn crossing_badge(session: &SimSession, time: f64) -> Option<String> {
    let crossings = session.crossing_at(time)?;
    let (a, b, _) = crossings.between.first()?;
    Some(if a.name() == b.name() {
        format!("CROSSING: {} through itself", a.name())
    } else {
        format!("CROSSING: {} / {}", a.name(), b.name())
    })
}

/// Colour of keyframes where organs cross.
pub const CROSSING_COLOUR: Color32 = Color32::from_rgb(200, 50, 50);
/// Colour of the current run's computed keyframes.
const COMPUTED_COLOUR: Color32 = Color32::from_rgb(90, 140, 90);
/// Colour of the current run's proxy keyframes (the converged ones are
/// coming).
pub const PROXY_COLOUR: Color32 = Color32::from_rgb(70, 130, 170);
/// Colour of stale keyframes (an earlier run's, still shown).
const STALE_COLOUR: Color32 = Color32::from_rgb(150, 125, 70);
/// Colour of the playhead and of the key being painted.
const PLAYHEAD_COLOUR: Color32 = Color32::from_rgb(230, 120, 40);

/// The timeline panel: the scrubber moves `playback` directly; the
/// buttons' commands are returned.
pub fn timeline_ui(
    ui: &mut egui::Ui,
    playback: &mut Playback,
    session: &SimSession,
    keys: &KeyMarks,
) -> Vec<Command> {
    let mut chosen = Vec::new();
    let shown = session.shown_end();
    let total = session.total().max(1);
    ui.horizontal(|ui| {
        if ui
            .button("Start")
            .on_hover_text("First keyframe (Home)")
            .clicked()
        {
            chosen.push(Command::GoToStart);
        }
        if ui
            .button("Prev")
            .on_hover_text("Previous keyframe (←)")
            .clicked()
        {
            chosen.push(Command::StepKeyframe(-1));
        }
        let play_label = if playback.playing { "Pause" } else { "Play" };
        if ui
            .button(play_label)
            .on_hover_text("Play or pause (Space)")
            .clicked()
        {
            chosen.push(Command::TogglePlay);
        }
        if ui
            .button("Next")
            .on_hover_text("Next keyframe (→)")
            .clicked()
        {
            chosen.push(Command::StepKeyframe(1));
        }
        if ui
            .button("End")
            .on_hover_text("Newest keyframe, and follow new ones (End)")
            .clicked()
        {
            chosen.push(Command::GoToEnd);
        }
        ui.toggle_value(&mut playback.looping, "Loop")
            .on_hover_text("Start again from the bud at the end");
        egui::ComboBox::new("speed", "speed")
            .width(70.0)
            .selected_text(format!("{}×", playback.speed))
            .show_ui(ui, |ui| {
                for speed in SPEEDS {
                    ui.selectable_value(&mut playback.speed, speed, format!("{speed}×"));
                }
            })
            .response
            .on_hover_text(format!(
                "Playback speed; 1× plays {BASE_KEYFRAMES_PER_SECOND} keyframes per second"
            ));
        if let Some(reached) = playback.reached_keyframes_per_second()
            && reached < 0.95 * playback.wanted_keyframes_per_second()
        {
            ui.label(
                egui::RichText::new(format!("{reached:.0} keyframes/s reached"))
                    .color(STALE_COLOUR),
            )
            .on_hover_text(format!(
                "Playback reaches {reached:.1} of the {:.0} keyframes per second the speed \
                 asks for: the window draws fewer than {:.0} frames per second here",
                playback.wanted_keyframes_per_second(),
                1.0 / MAX_FRAME_SECONDS
            ));
        }
        ui.separator();
        ui.label(format!(
            "keyframe {:.1} / {}",
            playback.time_in_keyframes,
            session.total()
        ));
        ui.separator();
        ui.label(status_line(session));
        if let Some(stale) = stale_line(session, playback.time_in_keyframes) {
            let colour = viewport_badge(session, playback.time_in_keyframes)
                .map_or(STALE_COLOUR, |(_, c)| c);
            ui.separator();
            ui.label(egui::RichText::new(stale).color(colour))
                .on_hover_text(
                    "The edit started a new run. The viewed keyframe shows a coarse proxy of \
                     the edited flower (blue), computed first, or the result from before the \
                     edit (brown), until the full-resolution run has computed it; then that \
                     replaces it.",
                );
        }
        ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
            if session.is_running() {
                if ui
                    .button("Stop")
                    .on_hover_text("Stop simulating; the keyframes so far stay")
                    .clicked()
                {
                    chosen.push(Command::StopSimulation);
                }
            } else if ui
                .button("Simulate")
                .on_hover_text("Simulate again from the bud")
                .clicked()
            {
                chosen.push(Command::Resimulate);
            }
        });
    });
    scrubber(ui, playback, session, keys, shown, total);
    stats_plot(ui, session, playback.time_in_keyframes);
    chosen
}

/// The scrubber: one cell per keyframe, filled where computed (green),
/// shown from the proxy (blue) or from an earlier run (stale, brown); the
/// time keys; the playhead;
/// click or drag to scrub.
fn scrubber(
    ui: &mut egui::Ui,
    playback: &mut Playback,
    session: &SimSession,
    keys: &KeyMarks,
    shown: Option<u32>,
    total: u32,
) {
    let size = Vec2::new(ui.available_width(), 22.0);
    let (rect, response) = ui.allocate_exact_size(size, Sense::click_and_drag());
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Slider, true, "Timeline"));
    // No tooltip while the playhead is dragged: it would cover the
    // keyframe read-out above the scrubber, the one thing to read then.
    let scrubbing = response.is_pointer_button_down_on() || response.dragged();
    let response = if scrubbing {
        response
    } else {
        response.on_hover_text(format!(
            "Timeline: green cells are computed keyframes, blue ones the coarse proxy (shown \
         until the full-resolution run reaches them), brown ones the previous result \
         (stale, shown until the new run reaches them), empty ones pending; a red bar marks \
         a keyframe where organs pass through each other (the log says which). Triangles mark \
         the time keys of {} (filled: the key being painted). Click or drag to scrub.",
            keys.template
        ))
    };
    let x_of = |time: f64| rect.left() + (time / f64::from(total)) as f32 * rect.width();
    if (response.dragged() || response.clicked())
        && let Some(pointer) = response.interact_pointer_pos()
    {
        let time = f64::from((pointer.x - rect.left()) / rect.width()) * f64::from(total);
        playback.scrub_to(time, shown);
    }
    let painter = ui.painter_at(rect);
    let visuals = ui.visuals();
    painter.rect_filled(rect, 3.0, visuals.extreme_bg_color);
    // Runs of cells in one state, each a rectangle from the keyframe
    // before the run to its last one.
    let colour_of = |state: FrameState| match state {
        FrameState::Converged => COMPUTED_COLOUR,
        FrameState::Proxy => PROXY_COLOUR,
        FrameState::Stale => STALE_COLOUR,
    };
    let end = shown.unwrap_or(0);
    let mut k = 1;
    while k <= end {
        let Some(state) = session.frame_state(k as usize) else {
            break;
        };
        let mut last = k;
        while last < end && session.frame_state(last as usize + 1) == Some(state) {
            last += 1;
        }
        let cells = Rect::from_min_max(
            Pos2::new(x_of(f64::from(k - 1)), rect.top()),
            Pos2::new(x_of(f64::from(last)), rect.bottom()),
        );
        painter.rect_filled(cells, 0.0, colour_of(state));
        k = last + 1;
    }
    // Keyframes where organs cross: a red bar along the cell's bottom.
    for k in session.crossed_keyframes().filter(|&k| k >= 1 && k <= end) {
        let bar = Rect::from_min_max(
            Pos2::new(x_of(f64::from(k - 1)), rect.bottom() - 6.0),
            Pos2::new(
                x_of(f64::from(k)).max(x_of(f64::from(k - 1)) + 2.0),
                rect.bottom(),
            ),
        );
        painter.rect_filled(bar, 0.0, CROSSING_COLOUR);
    }
    // Keyframe ticks: every keyframe when they are far enough apart,
    // otherwise every 10th.
    let every = if rect.width() / total as f32 > 4.0 {
        1
    } else {
        10
    };
    for k in (0..=total).step_by(every) {
        let x = x_of(f64::from(k));
        let tall = k % 10 == 0;
        let top = if tall { rect.top() } else { rect.center().y };
        painter.line_segment(
            [Pos2::new(x, top), Pos2::new(x, rect.bottom())],
            Stroke::new(1.0, visuals.weak_text_color().gamma_multiply(0.6)),
        );
    }
    painter.rect_stroke(
        rect,
        3.0,
        Stroke::new(1.0, visuals.widgets.noninteractive.bg_stroke.color),
        StrokeKind::Inside,
    );
    // Keys past the last keyframe still shape the blend before it, but
    // have no place on the timeline.
    for (i, &step) in keys.steps.iter().enumerate().filter(|(_, s)| **s <= total) {
        let x = x_of(f64::from(step));
        let triangle = vec![
            Pos2::new(x - 4.5, rect.top()),
            Pos2::new(x + 4.5, rect.top()),
            Pos2::new(x, rect.top() + 7.0),
        ];
        let fill = if keys.painted == Some(i) {
            PLAYHEAD_COLOUR
        } else {
            Color32::from_gray(235)
        };
        painter.add(egui::Shape::convex_polygon(
            triangle,
            fill,
            Stroke::new(1.0, Color32::from_gray(40)),
        ));
    }
    let x = x_of(playback.time_in_keyframes);
    painter.line_segment(
        [Pos2::new(x, rect.top()), Pos2::new(x, rect.bottom())],
        Stroke::new(2.5, PLAYHEAD_COLOUR),
    );
}

/// Energy (line) and Newton iterations (bars) per keyframe.
fn stats_plot(ui: &mut egui::Ui, session: &SimSession, time: f64) {
    let total = session.total().max(1);
    let size = Vec2::new(ui.available_width(), 56.0);
    let (rect, response) = ui.allocate_exact_size(size, Sense::hover());
    response.widget_info(|| {
        egui::WidgetInfo::labeled(
            egui::Role::Image,
            true,
            "Energy and iterations per keyframe",
        )
    });
    let painter = ui.painter_at(rect);
    let visuals = ui.visuals();
    painter.rect_filled(rect, 2.0, visuals.faint_bg_color);
    let stats: Vec<_> = session.stats().copied().collect();
    let x_of = |k: u32| rect.left() + k as f32 / total as f32 * rect.width();
    let max_iterations = stats.iter().map(|s| s.iterations).max().unwrap_or(1).max(1);
    let bar_width = (rect.width() / total as f32 * 0.6).max(1.0);
    for s in &stats {
        // The top 14 points hold the caption.
        let h = s.iterations as f32 / max_iterations as f32 * (rect.height() - 16.0);
        let x = x_of(s.index);
        painter.rect_filled(
            Rect::from_min_max(
                Pos2::new(x - bar_width, rect.bottom() - h),
                Pos2::new(x, rect.bottom()),
            ),
            0.0,
            Color32::from_rgb(110, 130, 190).gamma_multiply(0.6),
        );
    }
    let max_energy = stats.iter().map(|s| s.energy).fold(0.0_f64, f64::max);
    if max_energy > 0.0 {
        let points: Vec<Pos2> = stats
            .iter()
            .map(|s| {
                let y =
                    rect.bottom() - 2.0 - (s.energy / max_energy) as f32 * (rect.height() - 18.0);
                Pos2::new(x_of(s.index), y)
            })
            .collect();
        painter.line(points, Stroke::new(1.5, Color32::from_rgb(220, 90, 60)));
    }
    let x = rect.left() + (time / f64::from(total)) as f32 * rect.width();
    painter.line_segment(
        [Pos2::new(x, rect.top()), Pos2::new(x, rect.bottom())],
        Stroke::new(1.0, PLAYHEAD_COLOUR),
    );
    painter.text(
        rect.left_top() + Vec2::new(4.0, 2.0),
        egui::Align2::LEFT_TOP,
        format!(
            "energy (line, max {max_energy:.3e}) · Newton iterations (bars, max {max_iterations})"
        ),
        egui::FontId::proportional(10.0),
        visuals.weak_text_color(),
    );
    let hovered = stats
        .iter()
        .min_by_key(|s| {
            response
                .hover_pos()
                .map_or(u32::MAX, |p| (p.x - x_of(s.index)).abs() as u32)
        })
        .filter(|_| response.hovered());
    if let Some(s) = hovered {
        response.on_hover_text(format!(
            "keyframe {}: energy {:.4e}, {} iterations, {:.2} s",
            s.index, s.energy, s.iterations, s.seconds
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seconds_read_as_a_person_would_say_them() {
        assert_eq!(format_seconds(0.0), "under 0.1 s");
        assert_eq!(format_seconds(0.3), "0.3 s");
        assert_eq!(format_seconds(1.0), "1.0 s");
        assert_eq!(format_seconds(9.94), "9.9 s");
        assert_eq!(format_seconds(9.96), "10 s");
        assert_eq!(format_seconds(59.4), "59 s");
        assert_eq!(format_seconds(59.6), "1 min 0 s");
        assert_eq!(format_seconds(119.7), "2 min 0 s");
        assert_eq!(format_seconds(3725.2), "62 min 5 s");
        assert_eq!(format_seconds(f64::NAN), "an unknown time");
    }

    #[test]
    fn playing_waits_at_the_newest_keyframe_and_loops_only_a_finished_run() {
        let mut p = Playback {
            follow: false,
            playing: true,
            ..Playback::default()
        };
        // One second at 1x (four frames of a quarter second) is 24
        // keyframes; only 10 are computed of 100.
        let second = |p: &mut Playback, computed| {
            for _ in 0..4 {
                p.advance(0.25, Some(computed), 100);
            }
        };
        second(&mut p, 10);
        assert_eq!(p.time_in_keyframes, 10.0);
        assert!(p.playing, "waits for more keyframes");
        p.time_in_keyframes = 95.0;
        p.advance(0.25, Some(100), 100);
        p.advance(0.25, Some(100), 100);
        assert!(
            (p.time_in_keyframes - 7.0).abs() < 1e-9,
            "looped to {}",
            p.time_in_keyframes
        );
        p.looping = false;
        p.time_in_keyframes = 95.0;
        p.advance(0.25, Some(100), 100);
        p.advance(0.25, Some(100), 100);
        assert_eq!(p.time_in_keyframes, 100.0);
        assert!(!p.playing);
    }

    #[test]
    fn playing_keeps_real_time_down_to_four_frames_a_second_and_says_when_slower() {
        let mut p = Playback {
            follow: false,
            playing: true,
            ..Playback::default()
        };
        // 5 frames per second: every frame advances 0.2 s of keyframes.
        for _ in 0..10 {
            p.advance(0.2, Some(100), 100);
        }
        assert!((p.time_in_keyframes - 48.0).abs() < 1e-9);
        let reached = p.reached_keyframes_per_second().expect("measured");
        assert!((reached - 24.0).abs() < 1e-9, "{reached}");
        // 2 frames per second: each frame counts only 0.25 s.
        p.time_in_keyframes = 0.0;
        for _ in 0..10 {
            p.advance(0.5, Some(100), 100);
        }
        assert!((p.time_in_keyframes - 60.0).abs() < 1e-9);
        let reached = p.reached_keyframes_per_second().expect("measured");
        assert!((reached - 12.0).abs() < 0.5, "{reached}");
        // Waiting for the simulation is not the window's slowness.
        let mut waiting = Playback {
            follow: false,
            playing: true,
            ..Playback::default()
        };
        for _ in 0..10 {
            waiting.advance(0.2, Some(3), 100);
        }
        assert_eq!(waiting.reached_keyframes_per_second(), None);
        p.playing = false;
        p.advance(0.2, Some(100), 100);
        assert_eq!(p.reached_keyframes_per_second(), None);
    }

    #[test]
    fn stepping_lands_on_whole_keyframes_and_follow_tracks_the_newest() {
        let mut p = Playback::default();
        p.advance(0.1, Some(7), 100);
        assert_eq!(p.time_in_keyframes, 7.0, "follows new keyframes");
        p.scrub_to(3.4, Some(7));
        p.step(1, Some(7));
        assert_eq!(p.time_in_keyframes, 4.0);
        p.step(-1, Some(7));
        assert_eq!(p.time_in_keyframes, 3.0);
        p.step(-1, Some(7));
        assert_eq!(p.time_in_keyframes, 2.0);
        p.advance(0.1, Some(8), 100);
        assert_eq!(p.time_in_keyframes, 2.0, "scrubbing stops following");
        p.go_to_end(Some(8));
        p.advance(0.1, Some(9), 100);
        assert_eq!(p.time_in_keyframes, 9.0);
    }
}
