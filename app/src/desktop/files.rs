//! File dialogs: the native one (rfd) on its own thread so the window
//! keeps drawing while it is open, or, where no native dialog can be shown,
//! the in-app file browser (egui_file); the recent-files list; the
//! settings that eframe persists between launches.
//!
//! rfd's portal backend, when the desktop portal is missing, falls back to
//! `zenity`; when that is missing too it returns `None`, exactly as for a
//! cancel. So before the first native dialog the dialog thread checks
//! whether either can answer ([`native_dialog_missing`]: the portal's name
//! on the session bus, `zenity` on `PATH`); if neither can, the app says so
//! in the log and every dialog from then on is the in-app browser.

use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, TryRecvError, sync_channel};

use anthesis_sim::batch::Format;
use eframe::egui;

/// The file-name pattern of project files.
pub const PROJECT_EXTENSION: &str = "toml";

/// The D-Bus name of the desktop portal (whose FileChooser rfd asks).
const PORTAL_BUS_NAME: &str = "org.freedesktop.portal.Desktop";

/// What a file dialog was opened for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DialogPurpose {
    OpenProject,
    SaveProjectAs,
    ExportGlb,
    /// An OBJ mesh to make a new template of (the Flower panel).
    ImportTemplateObj,
    /// A scanned petal (an OBJ, UVs not needed) to fit (the Flower panel).
    ImportScan,
    /// An OBJ as the open shape of this template (two-state).
    OpenShape(usize),
    /// The target surface (an OBJ) of the growth-map fit.
    FitTarget,
}

impl DialogPurpose {
    fn title(self) -> &'static str {
        match self {
            DialogPurpose::OpenProject => "Open an Anthesis project",
            DialogPurpose::SaveProjectAs => "Save the project as",
            DialogPurpose::ExportGlb => "Export the animation (.glb, .usda, .usdc or .gif)",
            DialogPurpose::ImportTemplateObj => "Import an OBJ mesh as a new template",
            DialogPurpose::ImportScan => "Import a scanned petal (OBJ) to fit",
            DialogPurpose::OpenShape(_) => "Open shape: an OBJ of the template mesh moved",
            DialogPurpose::FitTarget => "Fit target: an OBJ surface",
        }
    }

    /// The file name offered when saving, for a project named
    /// `project_name`: an export is named as the export dialog names it
    /// ([`default_file_name`]).
    pub fn suggested_name(self, project_name: &str) -> Option<String> {
        match self {
            DialogPurpose::OpenProject
            | DialogPurpose::ImportTemplateObj
            | DialogPurpose::ImportScan
            | DialogPurpose::OpenShape(_)
            | DialogPurpose::FitTarget => None,
            DialogPurpose::SaveProjectAs => Some("flower.anthesis.toml".to_owned()),
            DialogPurpose::ExportGlb => Some(default_file_name(project_name)),
        }
    }

    /// The extensions of the files listed (and offered by the native
    /// dialog's filters).
    pub fn extensions(self) -> Vec<&'static str> {
        match self {
            DialogPurpose::OpenProject | DialogPurpose::SaveProjectAs => vec![PROJECT_EXTENSION],
            DialogPurpose::ExportGlb => Format::file_extensions(),
            DialogPurpose::ImportTemplateObj | DialogPurpose::ImportScan => vec!["obj"],
            DialogPurpose::OpenShape(_) | DialogPurpose::FitTarget => vec!["obj"],
        }
    }
}

/// Why no native file dialog can be shown, or `None` when one can: the
/// desktop portal owns (or can start) its name on the session bus, or
/// `zenity` is on `PATH` (rfd's fallback when the portal fails).
pub fn native_dialog_missing() -> Option<String> {
    if program_on_path("zenity", std::env::var_os("PATH").as_deref()) {
        return None;
    }
    match portal_on_session_bus() {
        Ok(true) => None,
        Ok(false) => Some(format!(
            "no desktop portal ({PORTAL_BUS_NAME} is not on the session bus) and no zenity on PATH"
        )),
        Err(e) => Some(format!(
            "no session bus to find the desktop portal on ({e}) and no zenity on PATH"
        )),
    }
}

/// Whether an executable file `name` is in one of the folders of `path`.
pub fn program_on_path(name: &str, path: Option<&std::ffi::OsStr>) -> bool {
    use std::os::unix::fs::PermissionsExt;
    let Some(path) = path else {
        return false;
    };
    std::env::split_paths(path).any(|folder| {
        std::fs::metadata(folder.join(name))
            .is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
    })
}

/// Whether the desktop portal is running or can be started on the session
/// bus.
fn portal_on_session_bus() -> zbus::Result<bool> {
    pollster::block_on(async {
        let connection = zbus::Connection::session().await?;
        let bus = zbus::fdo::DBusProxy::new(&connection).await?;
        let name = zbus::names::BusName::try_from(PORTAL_BUS_NAME)?;
        if bus.name_has_owner(name).await? {
            return Ok(true);
        }
        let activatable = bus.list_activatable_names().await?;
        Ok(activatable.iter().any(|n| n.as_str() == PORTAL_BUS_NAME))
    })
}

/// What the dialog thread answers.
enum Answer {
    /// The native dialog's answer (`None`: cancelled).
    Chosen(Option<PathBuf>),
    /// No native dialog can be shown, and why.
    NoNativeDialog(String),
}

/// What [`Dialogs::poll`] hands the app.
#[derive(Debug, Clone, PartialEq)]
pub enum Polled {
    /// The path chosen, or `None` when cancelled.
    Chosen(DialogPurpose, Option<PathBuf>),
    /// No native dialog can be shown (why): the in-app browser opened
    /// instead.
    InAppInstead(String),
}

/// A native dialog open: what for, where, the file name it offers, and
/// where its answer comes.
type Pending = (
    DialogPurpose,
    Option<PathBuf>,
    Option<String>,
    Receiver<Answer>,
);

/// At most one file dialog at a time: native ones answered on a thread
/// named `anthesis-dialog`, or the in-app browser.
#[derive(Default)]
pub struct Dialogs {
    /// The native dialog open, if any.
    pending: Option<Pending>,
    browser: Option<(DialogPurpose, egui_file::FileDialog)>,
    /// No native dialog can be shown: use the in-app browser.
    in_app: bool,
}

impl Dialogs {
    /// Dialogs that always use the in-app browser (for tests; the app
    /// switches by itself when no native dialog can be shown).
    pub fn in_app() -> Dialogs {
        Dialogs {
            in_app: true,
            ..Dialogs::default()
        }
    }

    pub fn is_open(&self) -> bool {
        self.pending.is_some() || self.browser.is_some()
    }

    /// Opens a dialog for `purpose` in `folder`, offering the file name
    /// `name` when saving; `wake` is called when a native one is answered.
    /// Does nothing while another dialog is open.
    pub fn open(
        &mut self,
        purpose: DialogPurpose,
        folder: Option<&Path>,
        name: Option<String>,
        wake: impl Fn() + Send + 'static,
    ) {
        if self.is_open() {
            return;
        }
        if self.in_app {
            self.open_browser(purpose, folder, name);
            return;
        }
        // One answer per dialog.
        let (send, receive) = sync_channel(1);
        let folder = folder.map(Path::to_path_buf);
        let thread_folder = folder.clone();
        let thread_name = name.clone();
        let spawned = std::thread::Builder::new()
            .name("anthesis-dialog".into())
            .spawn(move || {
                let answer = match native_dialog_missing() {
                    Some(why) => Answer::NoNativeDialog(why),
                    None => Answer::Chosen(native_dialog(purpose, thread_folder, thread_name)),
                };
                let _ = send.send(answer);
                wake();
            });
        if spawned.is_ok() {
            self.pending = Some((purpose, folder, name, receive));
        }
    }

    fn open_browser(
        &mut self,
        purpose: DialogPurpose,
        folder: Option<&Path>,
        name: Option<String>,
    ) {
        let start = folder
            .map(Path::to_path_buf)
            .or_else(|| std::env::current_dir().ok())
            .unwrap_or_default();
        let extensions = purpose.extensions();
        let listed: egui_file::Filter<PathBuf> = Box::new(move |path: &Path| {
            path.extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| extensions.iter().any(|x| e.eq_ignore_ascii_case(x)))
        });
        let mut browser = match purpose {
            DialogPurpose::OpenProject
            | DialogPurpose::ImportTemplateObj
            | DialogPurpose::ImportScan
            | DialogPurpose::OpenShape(_)
            | DialogPurpose::FitTarget => egui_file::FileDialog::open_file(),
            DialogPurpose::SaveProjectAs | DialogPurpose::ExportGlb => {
                egui_file::FileDialog::save_file()
            }
        }
        .title(purpose.title())
        .initial_path(start)
        .show_files_filter(listed)
        .show_rename(false)
        .default_size(egui::vec2(560.0, 420.0));
        if let Some(name) = name {
            browser = browser.default_filename(name);
        }
        browser.open();
        self.browser = Some((purpose, browser));
    }

    /// The in-app browser, when open: drawn; its answer once given.
    pub fn browser_ui(&mut self, ctx: &egui::Context) -> Option<(DialogPurpose, Option<PathBuf>)> {
        let (purpose, browser) = self.browser.as_mut()?;
        let purpose = *purpose;
        let answer = match browser.show(ctx).state() {
            egui_file::State::Open => return None,
            egui_file::State::Selected => browser.path().map(Path::to_path_buf),
            egui_file::State::Cancelled | egui_file::State::Closed => None,
        };
        self.browser = None;
        Some((purpose, answer))
    }

    /// The answer of the open native dialog, once there is one; when no
    /// native dialog could be shown, the in-app browser is opened instead.
    pub fn poll(&mut self) -> Option<Polled> {
        let (purpose, folder, name, receive) = self.pending.as_ref()?;
        let purpose = *purpose;
        match receive.try_recv() {
            Ok(Answer::Chosen(answer)) => {
                self.pending = None;
                Some(Polled::Chosen(purpose, answer))
            }
            Ok(Answer::NoNativeDialog(why)) => {
                let (folder, name) = (folder.clone(), name.clone());
                self.pending = None;
                self.in_app = true;
                self.open_browser(purpose, folder.as_deref(), name);
                Some(Polled::InAppInstead(why))
            }
            Err(TryRecvError::Empty) => None,
            Err(TryRecvError::Disconnected) => {
                self.pending = None;
                Some(Polled::Chosen(purpose, None))
            }
        }
    }
}

/// Shows the native dialog for `purpose` (blocks until answered).
fn native_dialog(
    purpose: DialogPurpose,
    folder: Option<PathBuf>,
    name: Option<String>,
) -> Option<PathBuf> {
    let name = name.unwrap_or_default();
    let mut dialog = rfd::FileDialog::new().set_title(purpose.title());
    if let Some(folder) = folder {
        dialog = dialog.set_directory(folder);
    }
    match purpose {
        DialogPurpose::OpenProject => dialog
            .add_filter("Anthesis project", &purpose.extensions())
            .pick_file(),
        DialogPurpose::OpenShape(_) | DialogPurpose::FitTarget => dialog
            .add_filter("OBJ mesh", &purpose.extensions())
            .pick_file(),
        DialogPurpose::SaveProjectAs => dialog
            .add_filter("Anthesis project", &purpose.extensions())
            .set_file_name(&name)
            .save_file(),
        DialogPurpose::ImportTemplateObj | DialogPurpose::ImportScan => dialog
            .add_filter("OBJ mesh", &purpose.extensions())
            .pick_file(),
        DialogPurpose::ExportGlb => Format::FILES
            .into_iter()
            .fold(dialog, |dialog, format| {
                dialog.add_filter(format.name(), format.extensions())
            })
            .set_file_name(&name)
            .save_file(),
    }
}

/// The file name an export of a project named `project_name` is offered
/// under, by the export dialog's field and by the file dialog alike: the
/// name with every character but ASCII letters, digits and `-` made `_`,
/// as a .glb ("Asiatic lily" → "Asiatic_lily.glb"); "flower.glb" for a
/// project without a name.
pub fn default_file_name(project_name: &str) -> String {
    let stem: String = project_name
        .trim()
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if stem.is_empty() {
        "flower.glb".to_owned()
    } else {
        format!("{stem}.glb")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_export_is_named_after_the_project() {
        assert_eq!(default_file_name("Asiatic lily"), "Asiatic_lily.glb");
        assert_eq!(default_file_name("five-petal"), "five-petal.glb");
        assert_eq!(default_file_name("Lys/été"), "Lys__t_.glb");
        assert_eq!(default_file_name("  "), "flower.glb");
    }

    #[test]
    fn a_program_is_found_on_path_only_where_it_is_and_executable() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().expect("temp dir");
        let tool = dir.path().join("zenity");
        std::fs::write(&tool, "#!/bin/sh\n").expect("write");
        let path = std::env::join_paths(["/nonexistent/bin".as_ref(), dir.path()]).expect("path");
        std::fs::set_permissions(&tool, std::fs::Permissions::from_mode(0o644)).expect("chmod");
        assert!(!program_on_path("zenity", Some(&path)), "not executable");
        std::fs::set_permissions(&tool, std::fs::Permissions::from_mode(0o755)).expect("chmod");
        assert!(program_on_path("zenity", Some(&path)));
        assert!(!program_on_path(
            "zenity",
            Some("/nonexistent/bin".as_ref())
        ));
        assert!(!program_on_path("zenity", None));
    }
}
