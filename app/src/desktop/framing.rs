//! Framing the camera on the flower: on demand ("Frame all"), once when
//! the first keyframes arrive, and again on the open flower when the run
//! finishes if the user has not moved the camera since.

use super::AnthesisApp;
use super::session::RunStatus;
use super::viewport::{self, SceneOrgan};

impl AnthesisApp {
    /// Frames the camera on the scene as it is shown now.
    pub fn frame_all(&mut self) {
        let scene = viewport::build_scene(
            self.doc.project(),
            &self.session,
            self.playback.time_in_keyframes,
            self.shows_others(),
        );
        if let Some(bounds) = viewport::scene_bounds(&scene) {
            self.camera.frame(bounds);
        }
    }

    /// Whether organs outside the run are shown (as buds).
    pub(super) fn shows_others(&self) -> bool {
        self.view.show_others || !self.single_organ_preview
    }

    /// Frames the camera on `scene` (the scene shown this frame) once the
    /// first keyframes are in, and on the whole opening when the run
    /// finishes if the camera was not moved in between.
    pub(super) fn frame_automatically(&mut self, scene: &[SceneOrgan]) {
        if !self.framed
            && self.session.last_index().is_some()
            && let Some((lo, hi)) = viewport::scene_bounds(scene)
        {
            // The open flower is wider than the bud: leave room.
            let centre = 0.5 * (lo + hi);
            let half = 0.5 * (hi - lo);
            let room = glam::DVec3::new(half.y.max(half.x), half.y, half.y.max(half.z)) * 1.3;
            self.camera.frame((centre - room, centre + room));
            self.framed = true;
            self.auto_camera = Some(self.camera);
        }
        if let Some(auto) = self.auto_camera
            && matches!(self.session.status(), RunStatus::Finished { .. })
        {
            if auto == self.camera {
                let last = f64::from(self.session.last_index().unwrap_or(0));
                let open = viewport::build_scene(
                    self.doc.project(),
                    &self.session,
                    last,
                    self.shows_others(),
                );
                let bounds = [viewport::scene_bounds(scene), viewport::scene_bounds(&open)]
                    .into_iter()
                    .flatten()
                    .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)));
                if let Some(bounds) = bounds {
                    self.camera.frame(bounds);
                }
            }
            self.auto_camera = None;
        }
    }
}
