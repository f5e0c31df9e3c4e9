//! What the window keeps between launches: the recent files, the project
//! open at exit, the view, the camera and playback (eframe stores it as
//! JSON).

use std::path::{Path, PathBuf};

use anthesis_render::OrbitCamera;

use super::timeline::Playback;
use super::viewport::ViewOptions;

/// Most recent files remembered.
pub const RECENT_LIMIT: usize = 10;

/// What eframe stores between launches (besides window and panel layout,
/// which it keeps itself).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct Settings {
    pub recent: Vec<PathBuf>,
    /// The project open at the last exit, reopened at start.
    pub last_project: Option<PathBuf>,
    pub view: ViewOptions,
    pub camera: Option<OrbitCamera>,
    pub single_organ_preview: bool,
    pub looping: bool,
    pub speed: f64,
    pub show_log: bool,
    /// The undo history window is open.
    pub show_history: bool,
    /// Unsaved work is saved for recovery at most this often, in seconds.
    pub autosave_seconds: u64,
}

impl Default for Settings {
    fn default() -> Self {
        let playback = Playback::default();
        Settings {
            recent: Vec::new(),
            last_project: None,
            view: ViewOptions::default(),
            camera: None,
            single_organ_preview: false,
            looping: playback.looping,
            speed: playback.speed,
            show_log: true,
            show_history: false,
            autosave_seconds: super::autosave::DEFAULT_INTERVAL_SECONDS,
        }
    }
}

impl Settings {
    /// Puts `path` first in the recent list.
    pub fn remember(&mut self, path: &Path) {
        self.recent.retain(|p| p != path);
        self.recent.insert(0, path.to_path_buf());
        self.recent.truncate(RECENT_LIMIT);
    }

    pub fn forget(&mut self, path: &Path) {
        self.recent.retain(|p| p != path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recent_files_are_unique_newest_first_and_bounded() {
        let mut s = Settings::default();
        for i in 0..15 {
            s.remember(Path::new(&format!("/p/{i}.toml")));
        }
        s.remember(Path::new("/p/12.toml"));
        assert_eq!(s.recent.len(), RECENT_LIMIT);
        assert_eq!(s.recent[0], Path::new("/p/12.toml"));
        assert_eq!(s.recent[1], Path::new("/p/14.toml"));
        assert_eq!(
            s.recent.iter().filter(|p| p.ends_with("12.toml")).count(),
            1
        );
    }

    #[test]
    fn settings_survive_a_round_trip_and_old_files_get_defaults() {
        let mut s = Settings::default();
        s.remember(Path::new("/p/a.toml"));
        s.view.wireframe = true;
        let text = serde_json::to_string(&s).expect("serialises");
        let back: Settings = serde_json::from_str(&text).expect("reads back");
        assert_eq!(back, s);
        let partial: Settings = serde_json::from_str(r#"{"show_log": false}"#).expect("partial");
        assert!(!partial.show_log);
        assert_eq!(partial.speed, 1.0);
    }
}
