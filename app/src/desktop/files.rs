//! Native file dialogs (rfd) on their own thread so the window keeps
//! drawing while one is open, the recent-files list, and the settings that
//! eframe persists between launches.

use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, TryRecvError, sync_channel};

use anthesis_render::OrbitCamera;

use super::timeline::Playback;
use super::viewport::ViewOptions;

/// Most recent files remembered.
pub const RECENT_LIMIT: usize = 10;

/// The file-name pattern of project files.
pub const PROJECT_EXTENSION: &str = "toml";

/// What a file dialog was opened for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DialogPurpose {
    OpenProject,
    SaveProjectAs,
    ExportGlb,
}

/// At most one native dialog at a time, answered on a thread named
/// `anthesis-dialog`.
#[derive(Default)]
pub struct Dialogs {
    pending: Option<(DialogPurpose, Receiver<Option<PathBuf>>)>,
}

impl Dialogs {
    pub fn is_open(&self) -> bool {
        self.pending.is_some()
    }

    /// Opens the native dialog for `purpose`; `wake` is called when it is
    /// answered. Does nothing while another dialog is open.
    pub fn open(
        &mut self,
        purpose: DialogPurpose,
        folder: Option<&Path>,
        wake: impl Fn() + Send + 'static,
    ) {
        if self.pending.is_some() {
            return;
        }
        // One answer per dialog.
        let (send, receive) = sync_channel(1);
        let folder = folder.map(Path::to_path_buf);
        let spawned = std::thread::Builder::new()
            .name("anthesis-dialog".into())
            .spawn(move || {
                let mut dialog = rfd::FileDialog::new();
                if let Some(folder) = folder {
                    dialog = dialog.set_directory(folder);
                }
                let answer = match purpose {
                    DialogPurpose::OpenProject => dialog
                        .set_title("Open an Anthesis project")
                        .add_filter("Anthesis project", &[PROJECT_EXTENSION])
                        .pick_file(),
                    DialogPurpose::SaveProjectAs => dialog
                        .set_title("Save the project as")
                        .add_filter("Anthesis project", &[PROJECT_EXTENSION])
                        .set_file_name("flower.anthesis.toml")
                        .save_file(),
                    DialogPurpose::ExportGlb => dialog
                        .set_title("Export the animation (.glb, .usda or .gif)")
                        .add_filter("glTF binary", &["glb"])
                        .add_filter("USD layer", &["usda", "usd"])
                        .add_filter("GIF animation", &["gif"])
                        .set_file_name("flower.glb")
                        .save_file(),
                };
                let _ = send.send(answer);
                wake();
            });
        if spawned.is_ok() {
            self.pending = Some((purpose, receive));
        }
    }

    /// The answer of the open dialog, once there is one (`None` inside
    /// when the user cancelled or no dialog could be shown).
    pub fn poll(&mut self) -> Option<(DialogPurpose, Option<PathBuf>)> {
        let (purpose, receive) = self.pending.as_ref()?;
        let purpose = *purpose;
        match receive.try_recv() {
            Ok(answer) => {
                self.pending = None;
                Some((purpose, answer))
            }
            Err(TryRecvError::Empty) => None,
            Err(TryRecvError::Disconnected) => {
                self.pending = None;
                Some((purpose, None))
            }
        }
    }
}

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
