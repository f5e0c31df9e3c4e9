//! Autosave and recovery. While the document has unsaved changes, a copy
//! of it goes to the recovery folder in the user's data directory
//! (`anthesis_flower::project::recovery`; never beside the user's own
//! files) at most every interval (60 s unless the settings say otherwise),
//! written on the thread `anthesis-autosave` so the window never waits for
//! the disk. A save, a discard or a clean exit removes it; after a crash or
//! a `kill -9` the next launch finds it and offers the work back. A
//! recovery that cannot be read is set aside as `damaged-*`; at launch the
//! newest three of those are kept and any set aside over 30 days ago are
//! removed, each removal said in the log.

use std::path::PathBuf;
use std::sync::mpsc::{Receiver, SyncSender, TryRecvError, TrySendError, sync_channel};
use std::thread::JoinHandle;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use anthesis_flower::Project;
use anthesis_flower::project::recovery::{Recovery, RecoveryFolder};
use eframe::egui;

use super::AnthesisApp;
use super::document::Document;

/// How often the open document is saved for recovery, at most, by default.
pub const DEFAULT_INTERVAL_SECONDS: u64 = 60;

enum Job {
    Write {
        project: Box<Project>,
        original: Option<PathBuf>,
    },
    Discard,
}

/// The autosave thread and when it last wrote.
pub struct Autosave {
    folder: RecoveryFolder,
    interval: Duration,
    /// The document revision last handed to the thread, and when.
    sent_revision: Option<u64>,
    sent_at: Instant,
    jobs: Option<SyncSender<Job>>,
    failures: Receiver<String>,
    thread: Option<JoinHandle<()>>,
}

impl Autosave {
    /// Starts the thread writing into `folder` at most every `interval`.
    pub fn start(folder: RecoveryFolder, interval: Duration) -> std::io::Result<Autosave> {
        // A write waiting and one running at most: a newer snapshot is
        // simply sent at the next tick.
        let (jobs, inbox) = sync_channel::<Job>(1);
        let (failed, failures) = sync_channel::<String>(4);
        let writer = folder.clone();
        let thread = std::thread::Builder::new()
            .name("anthesis-autosave".into())
            .spawn(move || {
                for job in inbox {
                    let result = match job {
                        Job::Write { project, original } => writer
                            .write(&project, original.as_deref(), unix_seconds_now())
                            .map_err(|e| format!("autosave failed: {e}")),
                        Job::Discard => writer
                            .discard()
                            .map_err(|e| format!("cannot remove the recovery files: {e}")),
                    };
                    if let Err(message) = result {
                        let _ = failed.try_send(message);
                    }
                }
            })?;
        Ok(Autosave {
            folder,
            interval,
            sent_revision: None,
            sent_at: Instant::now(),
            jobs: Some(jobs),
            failures,
            thread: Some(thread),
        })
    }

    pub fn folder(&self) -> &RecoveryFolder {
        &self.folder
    }

    /// Hands the document to the thread when it has changes not yet saved
    /// for recovery and the interval has passed. Returns how long until
    /// the next look is due, if one is (for the window's repaint).
    pub fn tick(&mut self, doc: &Document, now: Instant) -> Option<Duration> {
        if !doc.is_dirty() || self.sent_revision == Some(doc.revision()) {
            return None;
        }
        let since = now.saturating_duration_since(self.sent_at);
        if since < self.interval {
            return Some(self.interval - since);
        }
        let job = Job::Write {
            project: Box::new(doc.project().clone()),
            original: doc.path.clone(),
        };
        match self.jobs.as_ref().map(|jobs| jobs.try_send(job)) {
            Some(Ok(())) => {
                self.sent_revision = Some(doc.revision());
                self.sent_at = now;
                None
            }
            // The thread is still writing the last one: try again soon.
            Some(Err(TrySendError::Full(_))) => Some(Duration::from_secs(1)),
            Some(Err(TrySendError::Disconnected(_))) | None => None,
        }
    }

    /// Removes the recovery files (after the work was saved or thrown
    /// away). Queued behind a write in progress, so it always wins.
    pub fn discard(&mut self) {
        self.sent_revision = None;
        if let Some(jobs) = &self.jobs {
            let _ = jobs.send(Job::Discard);
        }
    }

    /// Messages of writes that failed since the last call.
    pub fn failures(&self) -> Vec<String> {
        let mut found = Vec::new();
        loop {
            match self.failures.try_recv() {
                Ok(message) => found.push(message),
                Err(TryRecvError::Empty | TryRecvError::Disconnected) => return found,
            }
        }
    }

    /// Waits until every job handed over is done (tests, and exit).
    pub fn finish(&mut self) {
        self.jobs = None;
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

impl Drop for Autosave {
    fn drop(&mut self) {
        self.finish();
    }
}

fn unix_seconds_now() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs())
}

/// "3 minutes ago" for a recovery saved at `saved` (Unix seconds).
pub fn age_in_words(saved: u64, now: u64) -> String {
    let seconds = now.saturating_sub(saved);
    match seconds {
        0..60 => "less than a minute ago".to_string(),
        60..120 => "1 minute ago".to_string(),
        120..7200 => format!("{} minutes ago", seconds / 60),
        7200..172_800 => format!("{} hours ago", seconds / 3600),
        _ => format!("{} days ago", seconds / 86_400),
    }
}

impl AnthesisApp {
    /// Turns autosave on, into `folder`, at most every `interval`; a
    /// recovery left in the folder by a launch that did not end cleanly is
    /// offered at the next frame.
    pub fn enable_autosave(&mut self, folder: RecoveryFolder, interval: Duration) {
        // A damaged recovery is said, kept aside (never replaced by the
        // next autosave) and, when its project is there, offered.
        let mut readable = None;
        for aside in folder.set_aside_damaged() {
            self.log.error(format!(
                "the recovered work is damaged ({}); it is kept at {}",
                aside.problem,
                aside.folder.display()
            ));
            readable = readable.or(aside.recovery);
        }
        // Damaged recoveries do not pile up: the newest few are kept, none
        // older than a month, and the log says what went.
        for pruned in folder.prune_damaged(unix_seconds_now()) {
            let when = age_in_words(pruned.set_aside_unix_seconds, unix_seconds_now());
            match pruned.error {
                None => self.log.info(format!(
                    "removed the damaged recovery {} (set aside {when}; {})",
                    pruned.folder.display(),
                    pruned.why
                )),
                Some(error) => self.log.warn(format!(
                    "cannot remove the damaged recovery {} ({}): {error}",
                    pruned.folder.display(),
                    pruned.why
                )),
            }
        }
        self.recovery_offer = folder.find().or(readable);
        match Autosave::start(folder, interval) {
            Ok(autosave) => self.autosave = Some(autosave),
            Err(e) => self
                .log
                .error(format!("cannot start autosave: {e}; save your work often")),
        }
    }

    /// The recovery offered to the user, if one waits for an answer.
    pub fn recovery_offer(&self) -> Option<&Recovery> {
        self.recovery_offer.as_ref()
    }

    /// Each frame: hands unsaved work to the autosave thread when due and
    /// reports its failures.
    pub(super) fn autosave_tick(&mut self, ctx: &egui::Context) {
        let Some(autosave) = self.autosave.as_mut() else {
            return;
        };
        // Not while a recovery waits for an answer: it would be replaced
        // by the document shown before the user chose.
        if self.recovery_offer.is_some() {
            return;
        }
        if let Some(wait) = autosave.tick(&self.doc, Instant::now()) {
            ctx.request_repaint_after(wait);
        }
        for failure in autosave.failures() {
            self.log.error(failure);
        }
    }

    /// The work was saved or thrown away: no recovery is needed.
    pub(super) fn discard_recovery(&mut self) {
        if let Some(autosave) = self.autosave.as_mut() {
            autosave.discard();
        }
    }

    /// Opens the offered recovery as an unsaved document belonging to its
    /// original file.
    pub fn recover(&mut self) {
        let Some(recovery) = self.recovery_offer.take() else {
            return;
        };
        match recovery.load() {
            Ok(project) => {
                let mut doc = Document::new(project, recovery.original.clone());
                doc.mark_unsaved();
                self.replace_document(doc);
                self.log.info(format!(
                    "recovered the work saved {}; save it to keep it",
                    age_in_words(recovery.saved_at_unix_seconds, unix_seconds_now())
                ));
            }
            Err(e) => {
                self.log.error(format!("cannot recover the work: {e}"));
                // Kept from the next autosave, which would replace it.
                let in_use = recovery
                    .project_file
                    .parent()
                    .filter(|folder| {
                        folder.parent() == self.autosave.as_ref().map(|a| a.folder().dir())
                    })
                    .filter(|folder| {
                        !folder
                            .file_name()
                            .is_some_and(|name| name.to_string_lossy().starts_with("damaged-"))
                    });
                if let (Some(folder), Some(autosave)) = (in_use, self.autosave.as_ref()) {
                    match autosave.folder().set_aside(folder, e.to_string()) {
                        Ok(aside) => self.log.info(format!(
                            "the recovery is kept at {}",
                            aside.folder.display()
                        )),
                        Err(error) => self
                            .log
                            .error(format!("cannot keep the recovery aside: {error}")),
                    }
                }
            }
        }
    }

    /// Throws the offered recovery away.
    pub fn discard_offered_recovery(&mut self) {
        if self.recovery_offer.take().is_some() {
            self.discard_recovery();
            self.log.info("discarded the recovered work");
        }
    }

    /// "Recover unsaved work?" at launch after a crash.
    pub(super) fn recovery_prompt(&mut self, ctx: &egui::Context) {
        let Some(recovery) = &self.recovery_offer else {
            return;
        };
        let what = match &recovery.original {
            Some(path) => format!(
                "Changes to {} were",
                path.file_name().map_or_else(
                    || path.display().to_string(),
                    |name| name.to_string_lossy().into_owned()
                )
            ),
            None => "A project that was never saved was".to_string(),
        };
        let when = age_in_words(recovery.saved_at_unix_seconds, unix_seconds_now());
        let mut answer = None;
        egui::Modal::new(egui::Id::unique("recover unsaved work")).show(ctx, |ui| {
            ui.heading("Recover unsaved work?");
            ui.label(format!(
                "Anthesis did not close normally. {what} saved for recovery {when}."
            ));
            ui.horizontal(|ui| {
                if ui.button("Recover").clicked() {
                    answer = Some(true);
                }
                if ui.button("Discard").clicked() {
                    answer = Some(false);
                }
            });
        });
        match answer {
            Some(true) => self.recover(),
            Some(false) => self.discard_offered_recovery(),
            None => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ages_read_naturally() {
        assert_eq!(age_in_words(100, 130), "less than a minute ago");
        assert_eq!(age_in_words(100, 170), "1 minute ago");
        assert_eq!(age_in_words(0, 600), "10 minutes ago");
        assert_eq!(age_in_words(0, 3 * 3600), "3 hours ago");
        assert_eq!(age_in_words(0, 3 * 86_400), "3 days ago");
        // A clock set back: never negative.
        assert_eq!(age_in_words(500, 100), "less than a minute ago");
    }

    fn edited_doc() -> Document {
        let mut doc = Document::new(anthesis_sim::fixtures::whorl(1, 6, 10, 3), None);
        doc.edit("rename", |p| p.name = "edited".into());
        doc
    }

    fn wait_for(folder: &RecoveryFolder, name: &str) -> Recovery {
        let deadline = Instant::now() + Duration::from_secs(30);
        loop {
            if let Some(found) = folder.find()
                && found.load().is_ok_and(|p| p.name == name)
            {
                return found;
            }
            assert!(Instant::now() < deadline, "no recovery of {name}");
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    #[test]
    fn unsaved_work_is_written_once_per_change_and_not_before_the_interval() {
        let dir = tempfile::tempdir().expect("tempdir");
        let folder = RecoveryFolder::new(dir.path());
        let mut autosave =
            Autosave::start(folder.clone(), Duration::from_secs(60)).expect("thread");
        let start = Instant::now();
        let clean = Document::new(anthesis_sim::fixtures::whorl(1, 6, 10, 3), None);
        assert_eq!(
            autosave.tick(&clean, start + Duration::from_secs(120)),
            None
        );
        let mut doc = edited_doc();
        // Too early: it says how long to wait.
        let wait = autosave.tick(&doc, start + Duration::from_secs(10));
        assert!(
            wait.is_some_and(|w| w <= Duration::from_secs(50)),
            "{wait:?}"
        );
        autosave.finish();
        assert_eq!(folder.find(), None, "nothing written before the interval");

        let mut autosave = Autosave::start(folder.clone(), Duration::ZERO).expect("thread");
        assert_eq!(autosave.tick(&doc, Instant::now()), None);
        wait_for(&folder, "edited");
        // The same revision is not written again; a new edit is.
        assert_eq!(autosave.tick(&doc, Instant::now()), None);
        doc.edit("rename", |p| p.name = "edited again".into());
        autosave.tick(&doc, Instant::now());
        let found = wait_for(&folder, "edited again");
        assert_eq!(found.original, None);
        // Discard removes it, after the write in progress.
        autosave.discard();
        autosave.finish();
        assert_eq!(folder.find(), None);
        assert!(autosave.failures().is_empty());
    }

    #[test]
    fn a_failed_write_is_reported() {
        let dir = tempfile::tempdir().expect("tempdir");
        // A file where the folder should be.
        let blocked = dir.path().join("recovery");
        std::fs::write(&blocked, "in the way").expect("write");
        let mut autosave =
            Autosave::start(RecoveryFolder::new(&blocked), Duration::ZERO).expect("thread");
        autosave.tick(&edited_doc(), Instant::now());
        let deadline = Instant::now() + Duration::from_secs(30);
        let failures = loop {
            let failures = autosave.failures();
            if !failures.is_empty() || Instant::now() > deadline {
                break failures;
            }
            std::thread::sleep(Duration::from_millis(10));
        };
        assert_eq!(failures.len(), 1, "{failures:?}");
        assert!(failures[0].starts_with("autosave failed: "), "{failures:?}");
    }
}
