//! Recovery files: the open document saved now and then into a folder of
//! the user's data directory (never beside the user's own files), so that
//! after a crash the next launch can offer the work back.
//!
//! The folder holds at most one recovery, `latest/`: a project saved as
//! usual (`recovered.anthesis.toml`, its meshes and maps) and
//! `recovery.toml` saying when it was saved and where the project lives.
//! A new recovery is written whole into a fresh `writing-*` folder and then
//! takes the place of `latest/` by renames, so a crash while writing leaves
//! the previous recovery readable (as `latest/`, or `previous/` between the
//! two renames).

use std::fs;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::{ProjectError, load_project, save_project};
use crate::Project;

const LATEST: &str = "latest";
const PREVIOUS: &str = "previous";
const WRITING_PREFIX: &str = "writing-";
const PROJECT_FILE: &str = "recovered.anthesis.toml";
const ABOUT_FILE: &str = "recovery.toml";
const DAMAGED_PREFIX: &str = "damaged-";

/// How many damaged recoveries are kept at most: the newest ones. A
/// recovery set aside at this launch is always among them.
pub const KEEP_DAMAGED: usize = 3;

/// How old a damaged recovery may get before it is removed, in days (30:
/// long enough for a user told at launch to have looked at it).
pub const KEEP_DAMAGED_DAYS: u64 = 30;

/// A damaged recovery [`RecoveryFolder::prune_damaged`] removed, for the
/// log.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Pruned {
    /// Where it was.
    pub folder: PathBuf,
    /// When it was set aside (Unix seconds).
    pub set_aside_unix_seconds: u64,
    /// Why it was removed ("older than 30 days", "more than the 3 kept").
    pub why: String,
    /// The error, if it could not be removed (it is then still there).
    pub error: Option<String>,
}

/// A recovery that could not be read whole, moved out of the way of the
/// next autosave (renamed `damaged-*` in the recovery folder, which
/// [`RecoveryFolder::write`] and [`RecoveryFolder::discard`] never touch).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SetAside {
    /// Where it is kept now.
    pub folder: PathBuf,
    /// What was wrong with it, for the user.
    pub problem: String,
    /// Its project, when the project file is there to be opened (the
    /// original and the time from its note when readable, else none and
    /// the file's modification time).
    pub recovery: Option<Recovery>,
}

/// What `recovery.toml` records.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
struct About {
    /// Seconds since the Unix epoch when the recovery was written.
    saved_at_unix_seconds: u64,
    /// The project file the work belongs to; absent for a project never
    /// saved.
    original: Option<PathBuf>,
}

/// A recovery found in the folder.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Recovery {
    /// The recovered project file (inside the recovery folder).
    pub project_file: PathBuf,
    /// The project file the work belongs to, if it had been saved.
    pub original: Option<PathBuf>,
    /// Seconds since the Unix epoch when it was written.
    pub saved_at_unix_seconds: u64,
}

impl Recovery {
    /// Reads the recovered project (as any project: confined to its folder).
    pub fn load(&self) -> Result<Project, ProjectError> {
        load_project(&self.project_file)
    }
}

/// The folder recovery files live in.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RecoveryFolder {
    dir: PathBuf,
}

impl RecoveryFolder {
    /// The recovery folder at `dir` (usually in the user's data
    /// directory); nothing is created until [`RecoveryFolder::write`].
    pub fn new(dir: impl Into<PathBuf>) -> RecoveryFolder {
        RecoveryFolder { dir: dir.into() }
    }

    /// The folder this recovery folder lives at.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Writes `project` as the recovery, replacing the previous one only
    /// once the new one is complete.
    pub fn write(
        &self,
        project: &Project,
        original: Option<&Path>,
        saved_at_unix_seconds: u64,
    ) -> Result<(), ProjectError> {
        let io = |path: &Path, error: std::io::Error| ProjectError::Io {
            path: path.to_path_buf(),
            message: error.to_string(),
        };
        fs::create_dir_all(&self.dir).map_err(|e| io(&self.dir, e))?;
        let writing = self
            .dir
            .join(format!("{WRITING_PREFIX}{}", std::process::id()));
        if writing.exists() {
            fs::remove_dir_all(&writing).map_err(|e| io(&writing, e))?;
        }
        save_project(project, &writing.join(PROJECT_FILE))?;
        let about = About {
            saved_at_unix_seconds,
            original: original.map(Path::to_path_buf),
        };
        let text = toml::to_string(&about).map_err(|e| ProjectError::Io {
            path: writing.join(ABOUT_FILE),
            message: e.to_string(),
        })?;
        anthesis_files::write_atomic(&writing.join(ABOUT_FILE), text.as_bytes()).map_err(|e| {
            ProjectError::Io {
                path: writing.join(ABOUT_FILE),
                message: e.to_string(),
            }
        })?;
        let latest = self.dir.join(LATEST);
        let previous = self.dir.join(PREVIOUS);
        if previous.exists() {
            fs::remove_dir_all(&previous).map_err(|e| io(&previous, e))?;
        }
        if latest.exists() {
            fs::rename(&latest, &previous).map_err(|e| io(&latest, e))?;
        }
        fs::rename(&writing, &latest).map_err(|e| io(&latest, e))?;
        if previous.exists() {
            fs::remove_dir_all(&previous).map_err(|e| io(&previous, e))?;
        }
        Ok(())
    }

    /// The recovery waiting in the folder, if any: `latest/`, or
    /// `previous/` when a write stopped between its two renames.
    /// Half-written folders are never offered.
    pub fn find(&self) -> Option<Recovery> {
        [LATEST, PREVIOUS]
            .iter()
            .find_map(|name| read_recovery(&self.dir.join(name)).ok())
    }

    /// Moves every recovery whose note (`recovery.toml`) or project file
    /// is missing or damaged out of the way, so that no autosave replaces
    /// it, and says what was wrong with each. Call before [`Self::find`]
    /// and before the first write of a launch.
    pub fn set_aside_damaged(&self) -> Vec<SetAside> {
        let mut set_aside = Vec::new();
        for name in [LATEST, PREVIOUS] {
            let folder = self.dir.join(name);
            if !folder.is_dir() {
                continue;
            }
            if let Err(problem) = read_recovery(&folder) {
                match self.set_aside(&folder, problem) {
                    Ok(aside) => set_aside.push(aside),
                    Err(error) => set_aside.push(SetAside {
                        folder: folder.clone(),
                        problem: format!("it could not be moved aside either: {error}"),
                        recovery: None,
                    }),
                }
            }
        }
        set_aside
    }

    /// Moves the recovery in `folder` aside as damaged (`problem`): a
    /// recovery whose project does not load is kept, never replaced.
    pub fn set_aside(&self, folder: &Path, problem: String) -> std::io::Result<SetAside> {
        let stamp = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_secs());
        let mut target = self.dir.join(format!("{DAMAGED_PREFIX}{stamp}"));
        let mut n = 1;
        while target.exists() {
            n += 1;
            target = self.dir.join(format!("{DAMAGED_PREFIX}{stamp}-{n}"));
        }
        fs::rename(folder, &target)?;
        let project_file = target.join(PROJECT_FILE);
        let recovery = project_file.is_file().then(|| {
            let about = read_about(&target).ok();
            let modified = fs::metadata(&project_file)
                .and_then(|m| m.modified())
                .ok()
                .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
                .map_or(0, |d| d.as_secs());
            Recovery {
                project_file: project_file.clone(),
                original: about.as_ref().and_then(|a| a.original.clone()),
                saved_at_unix_seconds: about.map_or(modified, |a| a.saved_at_unix_seconds),
            }
        });
        Ok(SetAside {
            folder: target,
            problem,
            recovery,
        })
    }

    /// Removes the damaged recoveries set aside longer than
    /// [`KEEP_DAMAGED_DAYS`] before `now_unix_seconds`, and all but the
    /// newest [`KEEP_DAMAGED`], so `damaged-*` folders do not pile up
    /// launch after launch. Only `damaged-*` folders are touched; each
    /// removal (or failed removal) is returned for the log. Call after
    /// [`Self::set_aside_damaged`], so a recovery set aside now is the
    /// newest and kept.
    pub fn prune_damaged(&self, now_unix_seconds: u64) -> Vec<Pruned> {
        let Ok(entries) = fs::read_dir(&self.dir) else {
            return Vec::new();
        };
        let mut damaged: Vec<(u64, PathBuf)> = entries
            .filter_map(Result::ok)
            .filter(|entry| {
                entry
                    .file_name()
                    .to_string_lossy()
                    .starts_with(DAMAGED_PREFIX)
                    && entry.file_type().is_ok_and(|t| t.is_dir())
            })
            .map(|entry| (set_aside_at(&entry.path()), entry.path()))
            .collect();
        // Newest first; equal stamps by name, for a stable order.
        damaged.sort_by(|a, b| b.0.cmp(&a.0).then_with(|| b.1.cmp(&a.1)));
        let max_age = KEEP_DAMAGED_DAYS * 86_400;
        let mut pruned = Vec::new();
        for (rank, (at, folder)) in damaged.into_iter().enumerate() {
            let why = if now_unix_seconds.saturating_sub(at) > max_age {
                format!("set aside more than {KEEP_DAMAGED_DAYS} days ago")
            } else if rank >= KEEP_DAMAGED {
                format!("only the newest {KEEP_DAMAGED} damaged recoveries are kept")
            } else {
                continue;
            };
            let error = fs::remove_dir_all(&folder).err().map(|e| e.to_string());
            pruned.push(Pruned {
                folder,
                set_aside_unix_seconds: at,
                why,
                error,
            });
        }
        pruned
    }

    /// Removes every recovery (after a save, a clean exit, or when the user
    /// discards it).
    pub fn discard(&self) -> std::io::Result<()> {
        let entries = match fs::read_dir(&self.dir) {
            Ok(entries) => entries,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
            Err(e) => return Err(e),
        };
        for entry in entries {
            let entry = entry?;
            let name = entry.file_name().to_string_lossy().into_owned();
            if name == LATEST || name == PREVIOUS || name.starts_with(WRITING_PREFIX) {
                fs::remove_dir_all(entry.path())?;
            }
        }
        Ok(())
    }
}

/// When the damaged recovery `folder` was set aside: the Unix seconds in
/// its name (`damaged-<seconds>[-<n>]`), else its modification time, else
/// 0 (the oldest).
fn set_aside_at(folder: &Path) -> u64 {
    let stamp = folder
        .file_name()
        .and_then(|name| name.to_str())
        .and_then(|name| name.strip_prefix(DAMAGED_PREFIX))
        .and_then(|rest| rest.split('-').next())
        .and_then(|seconds| seconds.parse::<u64>().ok());
    stamp.unwrap_or_else(|| {
        fs::metadata(folder)
            .and_then(|m| m.modified())
            .ok()
            .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
            .map_or(0, |d| d.as_secs())
    })
}

/// The recovery in `folder`, or what is wrong with it.
fn read_recovery(folder: &Path) -> Result<Recovery, String> {
    let project_file = folder.join(PROJECT_FILE);
    if !project_file.is_file() {
        return Err(format!("{} is missing", project_file.display()));
    }
    let about = read_about(folder)?;
    Ok(Recovery {
        project_file,
        original: about.original,
        saved_at_unix_seconds: about.saved_at_unix_seconds,
    })
}

/// `folder`'s `recovery.toml`, or what is wrong with it.
fn read_about(folder: &Path) -> Result<About, String> {
    let path = folder.join(ABOUT_FILE);
    let text = anthesis_files::read_regular_text(&path, 64 << 10, "a recovery note")
        .map_err(|e| format!("{} cannot be read: {e}", path.display()))?;
    toml::from_str(&text).map_err(|e| {
        format!(
            "{} is damaged: {}",
            path.display(),
            e.message().lines().next().unwrap_or("not a recovery note")
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Flower, SimulationSettings};

    /// A small valid project: one template, one organ.
    fn project(name: &str) -> Project {
        let mesh = anthesis_mesh::generate::test_petal(4.0, 1.5, 4, 6);
        let template = crate::Template {
            name: "petal".into(),
            mesh,
            maps: anthesis_maps::KeyedMaps::single(anthesis_maps::GrowthMaps::uniform()),
            dg: 0.003,
            thickness: 0.02,
            stretch_stiffness: 20.0,
            bend_stiffness: 20.0,
            base_region: crate::BaseRegion {
                v_max: 0.2,
                u_min: 0.0,
                u_max: 1.0,
            },
            joint_schedule: Vec::new(),
            colour: [1.0, 0.5, 0.5, 1.0],
            colouring: None,
            two_state: None,
            source: None,
            vein: None,
        };
        Project {
            name: name.into(),
            flower: Flower {
                templates: vec![template],
                organs: vec![crate::Organ {
                    name: "petal-1".into(),
                    template: 0,
                    placement: crate::Placement {
                        position: glam::DVec3::ZERO,
                        azimuth_deg: 0.0,
                        joint_angle_deg: 0.0,
                        orientation: glam::DQuat::IDENTITY,
                    },
                }],
                overlaps: Vec::new(),
                structure: None,
                parts: Vec::new(),
                unit: None,
            },
            settings: SimulationSettings::default(),
        }
    }

    #[test]
    fn a_written_recovery_is_found_and_loads_as_the_project_it_saved() {
        let dir = tempfile::tempdir().expect("tempdir");
        let folder = RecoveryFolder::new(dir.path().join("recovery"));
        assert_eq!(folder.find(), None, "nothing before the first write");
        let work = project("work");
        let original = dir.path().join("mine/flower.anthesis.toml");
        folder
            .write(&work, Some(&original), 1_700_000_000)
            .expect("write");
        let found = folder.find().expect("a recovery");
        assert_eq!(found.original.as_deref(), Some(original.as_path()));
        assert_eq!(found.saved_at_unix_seconds, 1_700_000_000);
        assert!(found.project_file.starts_with(folder.dir()));
        assert_eq!(found.load().expect("load"), work);
        // The user's folder was not touched.
        assert!(!dir.path().join("mine").exists());
    }

    #[test]
    fn a_newer_write_replaces_the_older_and_discard_removes_it() {
        let dir = tempfile::tempdir().expect("tempdir");
        let folder = RecoveryFolder::new(dir.path());
        folder.write(&project("first"), None, 1).expect("write");
        folder.write(&project("second"), None, 2).expect("write");
        let found = folder.find().expect("a recovery");
        assert_eq!(found.saved_at_unix_seconds, 2);
        assert_eq!(found.original, None);
        assert_eq!(found.load().expect("load").name, "second");
        folder.discard().expect("discard");
        assert_eq!(folder.find(), None);
        // Discarding nothing is fine, and so is a folder never made.
        folder.discard().expect("discard again");
        RecoveryFolder::new(dir.path().join("never"))
            .discard()
            .expect("no folder");
    }

    #[test]
    fn a_write_cut_short_leaves_the_previous_recovery() {
        let dir = tempfile::tempdir().expect("tempdir");
        let folder = RecoveryFolder::new(dir.path());
        folder.write(&project("kept"), None, 1).expect("write");
        // A crash while writing: a half-made folder beside the recovery,
        // its note missing.
        let half = dir.path().join("writing-99999");
        save_project(&project("half"), &half.join(PROJECT_FILE)).expect("save");
        assert_eq!(
            folder.find().expect("found").load().expect("load").name,
            "kept"
        );
        // A crash between the two renames: only `previous/` is there.
        fs::rename(dir.path().join(LATEST), dir.path().join(PREVIOUS)).expect("rename");
        assert_eq!(
            folder.find().expect("found").load().expect("load").name,
            "kept"
        );
        // The next write tidies up and wins.
        folder.write(&project("new"), None, 2).expect("write");
        assert_eq!(
            folder.find().expect("found").load().expect("load").name,
            "new"
        );
        folder.discard().expect("discard");
        assert_eq!(fs::read_dir(dir.path()).expect("list").count(), 0);
    }

    #[test]
    fn a_damaged_note_is_not_offered() {
        let dir = tempfile::tempdir().expect("tempdir");
        let folder = RecoveryFolder::new(dir.path());
        folder.write(&project("work"), None, 1).expect("write");
        fs::write(
            dir.path().join(LATEST).join(ABOUT_FILE),
            "saved_at_unix_seconds = \"x",
        )
        .expect("write");
        assert_eq!(folder.find(), None);
    }

    #[test]
    fn a_damaged_note_is_set_aside_kept_from_the_next_autosave_and_still_opens() {
        let dir = tempfile::tempdir().expect("tempdir");
        let folder = RecoveryFolder::new(dir.path().join("recovery"));
        let work = project("work");
        let original = dir.path().join("mine/flower.anthesis.toml");
        folder
            .write(&work, Some(&original), 1_700_000_000)
            .expect("write");
        let note = folder.dir().join(LATEST).join(ABOUT_FILE);
        fs::write(&note, "saved_at_unix_seconds = \"yesterday").expect("damage");
        let aside = folder.set_aside_damaged();
        assert_eq!(aside.len(), 1, "{aside:?}");
        assert!(
            aside[0].problem.contains("recovery.toml is damaged"),
            "{}",
            aside[0].problem
        );
        assert!(aside[0].folder.starts_with(folder.dir()));
        let recovery = aside[0].recovery.clone().expect("its project is there");
        assert_eq!(recovery.original, None, "the note is unreadable");
        assert_eq!(folder.find(), None, "not offered as a whole recovery");
        // The next autosave and a discard leave it where it is.
        folder
            .write(&project("later"), None, 1_700_000_100)
            .expect("write");
        folder.discard().expect("discard");
        assert_eq!(recovery.load().expect("what is readable opens"), work);
        // A folder without its project is set aside too.
        fs::create_dir_all(folder.dir().join(LATEST)).expect("mkdir");
        let aside = folder.set_aside_damaged();
        assert!(aside[0].problem.contains("is missing"), "{aside:?}");
        assert_eq!(aside[0].recovery, None);
    }

    #[test]
    fn damaged_recoveries_older_than_the_limit_or_beyond_the_newest_few_are_removed() {
        let dir = tempfile::tempdir().expect("tempdir");
        let folder = RecoveryFolder::new(dir.path());
        let day = 86_400;
        let now = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .expect("after 1970")
            .as_secs();
        // Five set aside 1, 2, 3 and 4 days ago and one 31 days ago; and a
        // folder that is not a damaged recovery, and a file named like one.
        let ages = [1, 2, 3, 4, 31];
        for age in ages {
            let aside = dir
                .path()
                .join(format!("{DAMAGED_PREFIX}{}", now - age * day));
            fs::create_dir_all(&aside).expect("mkdir");
            fs::write(aside.join(PROJECT_FILE), "x").expect("write");
        }
        fs::create_dir_all(dir.path().join(LATEST)).expect("mkdir");
        fs::write(dir.path().join(format!("{DAMAGED_PREFIX}note")), "x").expect("write");
        let pruned = folder.prune_damaged(now);
        let mut removed: Vec<(u64, &str)> = pruned
            .iter()
            .map(|p| ((now - p.set_aside_unix_seconds) / day, p.why.as_str()))
            .collect();
        removed.sort();
        assert_eq!(
            removed,
            [
                (4, "only the newest 3 damaged recoveries are kept"),
                (31, "set aside more than 30 days ago"),
            ]
        );
        assert!(
            pruned
                .iter()
                .all(|p| p.error.is_none() && !p.folder.exists())
        );
        let mut left: Vec<String> = fs::read_dir(dir.path())
            .expect("list")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        let mut expected: Vec<String> = [1, 2, 3]
            .iter()
            .map(|age| format!("{DAMAGED_PREFIX}{}", now - age * day))
            .chain([format!("{DAMAGED_PREFIX}note"), LATEST.to_string()])
            .collect();
        expected.sort();
        assert_eq!(left, expected);
        // Nothing more to remove the next time.
        assert_eq!(folder.prune_damaged(now), Vec::new());
        // A recovery set aside now is the newest, and kept.
        folder.write(&project("work"), None, 1).expect("write");
        fs::write(dir.path().join(LATEST).join(ABOUT_FILE), "x = \"").expect("damage");
        let aside = folder.set_aside_damaged();
        let pruned = folder.prune_damaged(set_aside_at(&aside[0].folder));
        assert!(aside[0].folder.exists(), "{pruned:?}");
        assert_eq!(pruned.len(), 1, "{pruned:?}");
    }
}
