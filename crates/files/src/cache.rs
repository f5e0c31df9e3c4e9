//! A content-addressed cache of derived files: a result that takes time to
//! make (a remeshed template) kept under the hash of everything it was made
//! from, so the next run, or the next process, reads it back instead.
//!
//! - **Keys** are SHA-256 digests ([`KeyHasher`]) of everything the result
//!   depends on, each field length-prefixed so that no two inputs hash the
//!   same bytes. SHA-256 (the RustCrypto `sha2` crate: pure Rust, no build
//!   script, widely reviewed) because a key collision would silently give a
//!   wrong result: a checksum like CRC-32 is not enough, and the inputs are
//!   small (a template mesh is well under a megabyte, hashed in about a
//!   millisecond), so a faster hash would not be noticed.
//! - **Entries** are files `<64 hex digits of the key>.bin`: a header
//!   ([`MAGIC`], [`FORMAT_VERSION`], the key again, the payload's length and
//!   its SHA-256) and the payload. Every read checks all of it; an entry
//!   that is truncated, corrupt, of another version, another key, or not
//!   readable is a miss, never an error and never a wrong payload, and the
//!   next [`Cache::put`] replaces it.
//! - **Writes** go through [`write_atomic`] (a temporary file beside it,
//!   renamed over it), so processes racing to write one entry each leave a
//!   complete file; readers see the old file or the new one.
//! - **Size**: after a write, the oldest entries (by modification time,
//!   which a hit refreshes) are removed until the folder holds at most
//!   [`Cache::max_bytes`] ([`DEFAULT_MAX_BYTES`], 256 MiB, unless set).
//! - **Where** ([`Cache::user`]): `$ANTHESIS_CACHE_DIR/<name>` when that
//!   variable is set (empty: no cache at all), else
//!   `$XDG_CACHE_HOME/anthesis/<name>`, else `$HOME/.cache/anthesis/<name>`.
//! - **Failures never stop the user**: a folder that cannot be made or
//!   written turns writing off for the rest of the process (the work is
//!   done uncached) and leaves one message for [`Cache::take_warning`].

use std::fs;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, SystemTime};

use sha2::{Digest, Sha256};

use crate::write::{create_folder, write_atomic};

/// The first bytes of every cache entry.
pub const MAGIC: [u8; 8] = *b"ANTHCACH";

/// The version of the entry layout (header and checksum; what the payload
/// holds is versioned by whoever makes the key). An entry of another
/// version is a miss.
pub const FORMAT_VERSION: u32 = 1;

/// The environment variable that sets the cache's root folder (the
/// subfolders are inside it); set and empty, it turns the cache off.
pub const CACHE_DIR_VARIABLE: &str = "ANTHESIS_CACHE_DIR";

/// The default bound on one cache folder's size, in bytes (256 MiB: some
/// hundreds of remeshed film-resolution templates, a few megabytes each).
pub const DEFAULT_MAX_BYTES: u64 = 256 << 20;

/// The file name ending of an entry.
const ENTRY_EXTENSION: &str = "bin";

/// Header: magic, version (u32), key (32 bytes), payload length (u64),
/// payload SHA-256 (32 bytes).
const HEADER_LEN: usize = 8 + 4 + 32 + 8 + 32;

/// How old a leftover temporary file (from a process killed mid-write) must
/// be before an eviction removes it: older than any write in progress.
const STALE_TEMPORARY: Duration = Duration::from_secs(3600);

/// The key of a cache entry: the SHA-256 of what the entry depends on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Key([u8; 32]);

impl Key {
    /// The key as 64 lower-case hex digits (the entry's file name).
    pub fn hex(&self) -> String {
        self.0.iter().map(|b| format!("{b:02x}")).collect()
    }

    /// The 32 bytes of the digest.
    pub fn bytes(&self) -> [u8; 32] {
        self.0
    }
}

/// Builds a [`Key`] from the inputs a result depends on. Every field is
/// written with its length (or is of fixed size), so the fields' bytes
/// cannot run into each other; floats are hashed by their bits (`-0.0` and
/// `0.0` are different keys, as they may be different results).
pub struct KeyHasher(Sha256);

impl KeyHasher {
    /// A hasher for results of kind `kind` (e.g. `"remesh"`), so keys of
    /// different kinds never meet.
    pub fn new(kind: &str) -> Self {
        let mut hasher = KeyHasher(Sha256::new());
        hasher.bytes(kind.as_bytes());
        hasher
    }

    /// Adds a byte string (its length first).
    pub fn bytes(&mut self, bytes: &[u8]) -> &mut Self {
        self.0.update((bytes.len() as u64).to_le_bytes());
        self.0.update(bytes);
        self
    }

    /// Adds an unsigned integer.
    pub fn u64(&mut self, value: u64) -> &mut Self {
        self.0.update(value.to_le_bytes());
        self
    }

    /// Adds a float by its bits.
    pub fn f64(&mut self, value: f64) -> &mut Self {
        self.u64(value.to_bits())
    }

    /// Adds a sequence of floats by their bits (the count first).
    pub fn f64s(&mut self, values: impl IntoIterator<Item = f64>) -> &mut Self {
        let bytes: Vec<u8> = values
            .into_iter()
            .flat_map(|value| value.to_bits().to_le_bytes())
            .collect();
        self.u64(bytes.len() as u64 / 8);
        self.0.update(&bytes);
        self
    }

    /// Adds a sequence of 32-bit unsigned integers (the count first).
    pub fn u32s(&mut self, values: impl IntoIterator<Item = u32>) -> &mut Self {
        let bytes: Vec<u8> = values
            .into_iter()
            .flat_map(|value| value.to_le_bytes())
            .collect();
        self.u64(bytes.len() as u64 / 4);
        self.0.update(&bytes);
        self
    }

    /// The key.
    pub fn finish(self) -> Key {
        Key(self.0.finalize().into())
    }
}

/// What a cache lookup found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// The result was read from the cache.
    Hit,
    /// The result was made (and written, if the cache could be written).
    Miss,
    /// The cache is off (no folder); the result was made.
    Off,
}

/// A folder of cache entries (see the module documentation), or none (off).
/// Shared between threads; every method takes `&self`.
#[derive(Debug)]
pub struct Cache {
    folder: Option<PathBuf>,
    max_bytes: u64,
    /// Set once a write failed: the rest of the process works uncached.
    unwritable: AtomicBool,
    /// Why writing stopped, until taken.
    warning: Mutex<Option<String>>,
}

impl Cache {
    /// No cache: every lookup misses and nothing is written.
    pub const fn off() -> Self {
        Cache {
            folder: None,
            max_bytes: DEFAULT_MAX_BYTES,
            unwritable: AtomicBool::new(false),
            warning: Mutex::new(None),
        }
    }

    /// A cache in `folder` (created at the first write), bounded by
    /// [`DEFAULT_MAX_BYTES`].
    pub fn in_folder(folder: impl Into<PathBuf>) -> Self {
        let mut cache = Cache::off();
        cache.folder = Some(folder.into());
        cache
    }

    /// The same cache bounded by `max_bytes` instead.
    pub fn with_max_bytes(mut self, max_bytes: u64) -> Self {
        self.max_bytes = max_bytes;
        self
    }

    /// The user's cache folder for results of kind `name` (see the module
    /// documentation for where it is), or [`Cache::off`] when
    /// [`CACHE_DIR_VARIABLE`] is set and empty or no folder is known.
    pub fn user(name: &str) -> Self {
        let variable = |key: &str| std::env::var_os(key);
        match user_folder(name, variable) {
            Some(folder) => Cache::in_folder(folder),
            None => Cache::off(),
        }
    }

    /// The folder entries are kept in, if the cache is on.
    pub fn folder(&self) -> Option<&Path> {
        self.folder.as_deref()
    }

    /// The bound on the folder's size, in bytes.
    pub fn max_bytes(&self) -> u64 {
        self.max_bytes
    }

    /// Where the entry of `key` is (or would be) kept.
    pub fn entry_path(&self, key: &Key) -> Option<PathBuf> {
        self.folder
            .as_ref()
            .map(|folder| folder.join(format!("{}.{ENTRY_EXTENSION}", key.hex())))
    }

    /// The payload kept under `key`, if there is a valid entry; anything
    /// else (no entry, a truncated, corrupt, foreign or unreadable one) is
    /// `None`. A hit marks the entry as recently used.
    pub fn get(&self, key: &Key) -> Option<Vec<u8>> {
        let path = self.entry_path(key)?;
        let bytes = fs::read(&path).ok()?;
        let payload = payload_of(&bytes, key)?;
        // Best effort: a read-only cache still serves hits.
        if let Ok(file) = fs::File::options().write(true).open(&path) {
            let _ = file.set_modified(SystemTime::now());
        }
        Some(payload.to_vec())
    }

    /// Keeps `payload` under `key` (replacing any entry there), then evicts
    /// the oldest entries beyond the size bound. A failure to write turns
    /// writing off for the rest of the process and is kept for
    /// [`Cache::take_warning`]; it is never an error for the caller.
    pub fn put(&self, key: &Key, payload: &[u8]) {
        let Some(path) = self.entry_path(key) else {
            return;
        };
        if self.unwritable.load(Ordering::Relaxed) {
            return;
        }
        let folder = crate::write::folder_of(&path);
        let written =
            create_folder(&folder, &path).and_then(|()| write_atomic(&path, &entry(key, payload)));
        match written {
            Ok(()) => evict(&folder, self.max_bytes, &path),
            Err(error) => {
                if !self.unwritable.swap(true, Ordering::Relaxed)
                    && let Ok(mut warning) = self.warning.lock()
                {
                    *warning = Some(format!(
                        "the cache in {} cannot be written, working without it ({error})",
                        folder.display()
                    ));
                }
            }
        }
    }

    /// The value kept under `key` when there is one that `decode` accepts,
    /// otherwise `make`'s, which is then kept (encoded by `encode`). An
    /// error from `make` is returned and nothing is kept. A valid entry
    /// that `decode` refuses (a payload of a layout the key did not
    /// capture) is a miss and is replaced.
    pub fn get_or_make<T, E>(
        &self,
        key: &Key,
        decode: impl FnOnce(&[u8]) -> Option<T>,
        make: impl FnOnce() -> Result<T, E>,
        encode: impl FnOnce(&T) -> Vec<u8>,
    ) -> Result<(T, Outcome), E> {
        if self.folder.is_none() {
            return make().map(|value| (value, Outcome::Off));
        }
        if let Some(value) = self.get(key).and_then(|payload| decode(&payload)) {
            return Ok((value, Outcome::Hit));
        }
        let value = make()?;
        self.put(key, &encode(&value));
        Ok((value, Outcome::Miss))
    }

    /// Why the cache stopped writing, once (later calls give `None` until
    /// another failure, which cannot come: writing stays off).
    pub fn take_warning(&self) -> Option<String> {
        self.warning.lock().ok().and_then(|mut w| w.take())
    }
}

/// The cache folder for `name` given the environment `variable` (see
/// [`Cache::user`]).
fn user_folder(
    name: &str,
    variable: impl Fn(&str) -> Option<std::ffi::OsString>,
) -> Option<PathBuf> {
    if let Some(root) = variable(CACHE_DIR_VARIABLE) {
        if root.is_empty() {
            return None;
        }
        return Some(PathBuf::from(root).join(name));
    }
    // The XDG base directory specification: a relative path is invalid
    // and ignored.
    let xdg = variable("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .filter(|path| path.is_absolute());
    let root = match xdg {
        Some(root) => root,
        None => PathBuf::from(variable("HOME").filter(|home| !home.is_empty())?).join(".cache"),
    };
    Some(root.join("anthesis").join(name))
}

/// The entry file for `payload` under `key`.
fn entry(key: &Key, payload: &[u8]) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(HEADER_LEN + payload.len());
    bytes.extend_from_slice(&MAGIC);
    bytes.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    bytes.extend_from_slice(&key.0);
    bytes.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&Sha256::digest(payload));
    bytes.extend_from_slice(payload);
    bytes
}

/// The payload of entry file `bytes` if it is a whole, valid entry of this
/// version for `key`.
fn payload_of<'a>(bytes: &'a [u8], key: &Key) -> Option<&'a [u8]> {
    let (header, payload) = bytes.split_at_checked(HEADER_LEN)?;
    let (magic, rest) = header.split_at(8);
    let (version, rest) = rest.split_at(4);
    let (stored_key, rest) = rest.split_at(32);
    let (length, checksum) = rest.split_at(8);
    let version = u32::from_le_bytes(version.try_into().ok()?);
    let length = u64::from_le_bytes(length.try_into().ok()?);
    let valid = magic == MAGIC
        && version == FORMAT_VERSION
        && stored_key == key.0
        && length == payload.len() as u64
        && checksum == Sha256::digest(payload).as_slice();
    valid.then_some(payload)
}

/// Removes the oldest entries of `folder` until it holds at most
/// `max_bytes` (never `keep`, the entry just written), and temporary files
/// left by killed writers. Best effort: another process may be evicting
/// too, so a file that has gone is not an error.
fn evict(folder: &Path, max_bytes: u64, keep: &Path) {
    let Ok(listing) = fs::read_dir(folder) else {
        return;
    };
    let now = SystemTime::now();
    let mut entries: Vec<(SystemTime, u64, PathBuf)> = Vec::new();
    for item in listing.filter_map(Result::ok) {
        let path = item.path();
        let Ok(meta) = item.metadata() else {
            continue;
        };
        if !meta.is_file() {
            continue;
        }
        let modified = meta.modified().unwrap_or(now);
        let name = item.file_name();
        let name = name.to_string_lossy();
        if name.starts_with('.') && name.ends_with(".tmp") {
            if now
                .duration_since(modified)
                .is_ok_and(|age| age > STALE_TEMPORARY)
            {
                let _ = fs::remove_file(&path);
            }
        } else if is_entry_name(&name) {
            entries.push((modified, meta.len(), path));
        }
    }
    let mut total: u64 = entries.iter().map(|(_, size, _)| size).sum();
    if total <= max_bytes {
        return;
    }
    entries.sort_by_key(|(modified, _, _)| *modified);
    for (_, size, path) in entries {
        if total <= max_bytes {
            break;
        }
        if path == keep {
            continue;
        }
        match fs::remove_file(&path) {
            Ok(()) => total -= size,
            Err(error) if error.kind() == io::ErrorKind::NotFound => total -= size,
            Err(_) => {}
        }
    }
}

/// Whether `name` is an entry's file name (64 hex digits and the
/// extension), so eviction touches nothing else in the folder.
fn is_entry_name(name: &str) -> bool {
    name.strip_suffix(ENTRY_EXTENSION)
        .and_then(|stem| stem.strip_suffix('.'))
        .is_some_and(|hex| hex.len() == 64 && hex.bytes().all(|b| b.is_ascii_hexdigit()))
}

#[cfg(test)]
mod tests;
