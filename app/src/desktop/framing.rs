//! Framing the camera on the flower: on demand ("Frame all"), when the
//! first keyframes of a project or of a preview switch arrive, wider as
//! the opening outgrows the view while the camera is left alone, and on
//! the whole opening when the run finishes if the user has not moved the
//! camera since.

use glam::DVec3;

use super::AnthesisApp;
use super::session::RunStatus;
use super::viewport::{self, SceneOrgan};

/// How far out the framed flower reaches, as a fraction of the way from
/// the viewport's centre to the middle of its shorter side: it fills
/// about this much of the shorter side.
pub const FRAMED_REACH: f64 = 0.8;

/// While the camera is left alone, the view widens once the shown flower
/// reaches this far out.
const WIDEN_AT_REACH: f64 = 0.95;

/// Every position of `scene`, in world space.
fn positions(scene: &[SceneOrgan]) -> Vec<DVec3> {
    scene
        .iter()
        .flat_map(|o| o.positions_in_world.iter().copied())
        .collect()
}

impl AnthesisApp {
    /// Frames the camera on the scene as it is shown now.
    pub fn frame_all(&mut self) {
        let scene = viewport::build_scene(
            self.doc.project(),
            &self.session,
            self.playback.time_in_keyframes,
            self.shows_others(),
        );
        self.camera.frame_points(&positions(&scene), FRAMED_REACH);
    }

    /// Frames the camera again when the next keyframes arrive (a new
    /// project, the preview switched).
    pub(super) fn reframe(&mut self) {
        self.framed = false;
        self.auto_camera = None;
    }

    /// Whether organs outside the run are shown (as buds).
    pub(super) fn shows_others(&self) -> bool {
        self.view.show_others || !self.single_organ_preview
    }

    /// Frames the camera on `scene` (the scene shown this frame) once the
    /// first keyframes are in; while the user leaves the camera alone,
    /// widens it when the opening flower reaches the edge and, when the
    /// run finishes, frames the bud and the open flower together.
    pub(super) fn frame_automatically(&mut self, scene: &[SceneOrgan]) {
        if self.needs_run || (self.framed && self.auto_camera.is_none()) {
            // Waiting for the run of what changed: the keyframes shown
            // (and a finished status) are still the previous run's.
            return;
        }
        let shown = positions(scene);
        if !self.framed && self.session.last_index().is_some() && !shown.is_empty() {
            self.camera.frame_points(&shown, FRAMED_REACH);
            self.framed = true;
            self.auto_camera = Some(self.camera);
        }
        let Some(auto) = self.auto_camera else {
            return;
        };
        if auto != self.camera {
            // The user moved the camera: leave it.
            self.auto_camera = None;
            return;
        }
        if matches!(self.session.status(), RunStatus::Finished { .. }) {
            let last = f64::from(self.session.last_index().unwrap_or(0));
            let open =
                viewport::build_scene(self.doc.project(), &self.session, last, self.shows_others());
            let bud = viewport::build_scene(self.doc.project(), &self.session, 0.0, true);
            let mut both = positions(&open);
            both.extend(positions(&bud));
            both.extend(shown);
            self.camera.frame_points(&both, FRAMED_REACH);
            self.auto_camera = None;
        } else if self.camera.reach_in_image(&shown) > WIDEN_AT_REACH {
            let mut widened = shown;
            widened.extend(positions(&viewport::build_scene(
                self.doc.project(),
                &self.session,
                0.0,
                self.shows_others(),
            )));
            self.camera.frame_points(&widened, FRAMED_REACH);
            self.auto_camera = Some(self.camera);
        }
    }
}
