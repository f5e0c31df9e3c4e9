use super::*;

fn key(text: &str) -> Key {
    let mut hasher = KeyHasher::new("test");
    hasher.bytes(text.as_bytes());
    hasher.finish()
}

fn temp() -> tempfile::TempDir {
    tempfile::tempdir().expect("a temporary folder")
}

/// The files in `folder`, sorted.
fn files(folder: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(folder)
        .expect("listed")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn a_payload_put_is_read_back_and_a_key_never_put_misses() {
    let dir = temp();
    // The folder is made at the first write, parents too.
    let cache = Cache::in_folder(dir.path().join("a/remesh"));
    assert_eq!(cache.get(&key("one")), None);
    cache.put(&key("one"), b"payload one");
    assert_eq!(cache.get(&key("one")).as_deref(), Some(&b"payload one"[..]));
    assert_eq!(cache.get(&key("two")), None);
    let path = cache.entry_path(&key("one")).expect("on");
    assert_eq!(
        path.file_name().expect("named").to_string_lossy(),
        format!("{}.bin", key("one").hex())
    );
    assert_eq!(key("one").hex().len(), 64);
    assert_eq!(cache.take_warning(), None);
    // An empty payload is a payload.
    cache.put(&key("empty"), b"");
    assert_eq!(cache.get(&key("empty")), Some(Vec::new()));
}

#[test]
fn get_or_make_makes_once_then_hits() {
    let dir = temp();
    let cache = Cache::in_folder(dir.path());
    let mut made = 0;
    let run = |made: &mut i32| {
        cache.get_or_make(
            &key("k"),
            |bytes| std::str::from_utf8(bytes).ok().map(str::to_string),
            || -> Result<String, ()> {
                *made += 1;
                Ok("value".to_string())
            },
            |value| value.as_bytes().to_vec(),
        )
    };
    assert_eq!(run(&mut made), Ok(("value".to_string(), Outcome::Miss)));
    assert_eq!(run(&mut made), Ok(("value".to_string(), Outcome::Hit)));
    assert_eq!(made, 1);
    // An error is returned and nothing is kept.
    let failed = cache.get_or_make(&key("bad"), |_| Some(0), || Err("no"), |_| vec![1]);
    assert_eq!(failed, Err("no"));
    assert!(!cache.entry_path(&key("bad")).expect("on").exists());
    // A payload the decoder refuses is a miss, made again and replaced.
    let refused = cache.get_or_make(
        &key("k"),
        |_| None::<String>,
        || Ok::<_, ()>("other".to_string()),
        |value| value.as_bytes().to_vec(),
    );
    assert_eq!(refused, Ok(("other".to_string(), Outcome::Miss)));
    assert_eq!(cache.get(&key("k")).as_deref(), Some(&b"other"[..]));
}

#[test]
fn an_off_cache_makes_every_time_and_writes_nothing() {
    let cache = Cache::off();
    assert_eq!(cache.folder(), None);
    cache.put(&key("k"), b"x");
    assert_eq!(cache.get(&key("k")), None);
    let made = cache.get_or_make(&key("k"), |_| Some(1), || Ok::<_, ()>(2), |_| Vec::new());
    assert_eq!(made, Ok((2, Outcome::Off)));
}

#[test]
fn damaged_foreign_and_misplaced_entries_are_misses_and_get_replaced() {
    let dir = temp();
    let cache = Cache::in_folder(dir.path());
    let k = key("k");
    let payload = b"the remeshed mesh, say".to_vec();
    cache.put(&k, &payload);
    let path = cache.entry_path(&k).expect("on");
    let good = fs::read(&path).expect("written");
    assert_eq!(good.len(), HEADER_LEN + payload.len());

    let mut damaged: Vec<(&str, Vec<u8>)> = Vec::new();
    for cut in [0, 1, 7, HEADER_LEN - 1, HEADER_LEN, good.len() - 1] {
        damaged.push(("truncated", good[..cut].to_vec()));
    }
    let mut longer = good.clone();
    longer.push(0);
    damaged.push(("longer", longer));
    for at in [
        0,
        8,
        12,
        HEADER_LEN - 40,
        HEADER_LEN - 1,
        HEADER_LEN,
        good.len() - 1,
    ] {
        let mut flipped = good.clone();
        flipped[at] ^= 0x10;
        damaged.push(("a flipped bit", flipped));
    }
    let mut foreign = good.clone();
    foreign[8..12].copy_from_slice(&(FORMAT_VERSION + 1).to_le_bytes());
    damaged.push(("another version", foreign));
    damaged.push((
        "not an entry",
        b"hello, this is not a cache entry".repeat(4),
    ));
    // A valid entry of another key under this key's name.
    let other = key("other");
    damaged.push(("another key's entry", entry(&other, &payload)));

    for (what, bytes) in damaged {
        fs::write(&path, &bytes).expect("damaged");
        assert_eq!(
            cache.get(&k),
            None,
            "{what} ({} bytes) was a hit",
            bytes.len()
        );
        let (value, outcome) = cache
            .get_or_make(
                &k,
                |bytes| Some(bytes.to_vec()),
                || Ok::<_, ()>(payload.clone()),
                Clone::clone,
            )
            .expect("made");
        assert_eq!((value, outcome), (payload.clone(), Outcome::Miss), "{what}");
        assert_eq!(fs::read(&path).expect("rewritten"), good, "{what}");
    }
    // A folder where the entry should be is a miss too (and stays).
    fs::remove_file(&path).expect("removed");
    fs::create_dir(&path).expect("a folder in its place");
    assert_eq!(cache.get(&k), None);
}

#[test]
fn an_unwritable_folder_works_uncached_with_one_warning() {
    let dir = temp();
    // A file where the cache folder's parent should be: no folder can be
    // made there, whoever runs the test (permissions would not stop root).
    let blocker = dir.path().join("not-a-folder");
    fs::write(&blocker, b"x").expect("a file");
    let cache = Cache::in_folder(blocker.join("remesh"));
    let mut made = 0;
    for _ in 0..3 {
        let result = cache.get_or_make(
            &key("k"),
            |_| Some(0),
            || -> Result<i32, ()> {
                made += 1;
                Ok(7)
            },
            |_| vec![1, 2, 3],
        );
        assert_eq!(result, Ok((7, Outcome::Miss)));
    }
    assert_eq!(made, 3);
    let warning = cache.take_warning().expect("a warning");
    assert!(
        warning.contains("cannot be written, working without it")
            && warning.contains("not-a-folder"),
        "{warning}"
    );
    assert_eq!(cache.take_warning(), None, "the warning is given once");
}

#[test]
fn the_oldest_entries_go_first_when_the_folder_outgrows_its_bound() {
    let dir = temp();
    let payload = vec![7u8; 1000];
    let size = (HEADER_LEN + payload.len()) as u64;
    // Room for three entries.
    let cache = Cache::in_folder(dir.path()).with_max_bytes(3 * size);
    let old = SystemTime::now() - Duration::from_secs(1000);
    let age = |name: &str, seconds: u64| {
        let path = cache.entry_path(&key(name)).expect("on");
        fs::File::options()
            .write(true)
            .open(path)
            .expect("open")
            .set_modified(old + Duration::from_secs(seconds))
            .expect("dated");
    };
    for (i, name) in ["a", "b", "c"].into_iter().enumerate() {
        cache.put(&key(name), &payload);
        age(name, i as u64);
    }
    // Something else in the folder is never evicted; a stale temporary
    // file is.
    fs::write(dir.path().join("README"), b"not an entry").expect("written");
    let stale = dir.path().join(".x.bin.abc123.tmp");
    fs::write(&stale, b"half").expect("written");
    fs::File::options()
        .write(true)
        .open(&stale)
        .expect("open")
        .set_modified(old - STALE_TEMPORARY)
        .expect("dated");
    // A hit on "a" makes it the most recently used.
    assert!(cache.get(&key("a")).is_some());
    cache.put(&key("d"), &payload);
    let mut expected: Vec<String> = ["a", "c", "d"]
        .iter()
        .map(|n| format!("{}.bin", key(n).hex()))
        .collect();
    expected.push("README".to_string());
    expected.sort();
    assert_eq!(files(dir.path()), expected);
    // An entry larger than the whole bound is still kept (the newest).
    let small = Cache::in_folder(dir.path()).with_max_bytes(10);
    small.put(&key("e"), &payload);
    assert_eq!(
        files(dir.path()),
        vec!["README".to_string(), format!("{}.bin", key("e").hex())]
    );
}

#[test]
fn concurrent_writers_and_readers_leave_one_valid_entry() {
    let dir = temp();
    let k = key("k");
    let payload: Vec<u8> = (0..200_000u32).flat_map(|i| i.to_le_bytes()).collect();
    std::thread::scope(|scope| {
        for i in 0..6 {
            let (folder, payload) = (dir.path(), &payload);
            std::thread::Builder::new()
                .name(format!("cache-test-{i}"))
                .spawn_scoped(scope, move || {
                    // Each thread its own Cache value, as separate
                    // processes would have.
                    let cache = Cache::in_folder(folder);
                    for _ in 0..5 {
                        if i % 2 == 0 {
                            cache.put(&k, payload);
                        } else if let Some(read) = cache.get(&k) {
                            assert!(read == *payload, "a reader saw a partial entry");
                        }
                    }
                })
                .expect("thread");
        }
    });
    let cache = Cache::in_folder(dir.path());
    assert_eq!(cache.get(&k).as_deref(), Some(payload.as_slice()));
    assert_eq!(files(dir.path()), vec![format!("{}.bin", k.hex())]);
}

#[test]
fn the_user_folder_follows_the_environment() {
    let env = |pairs: &'static [(&'static str, &'static str)]| {
        move |name: &str| {
            pairs
                .iter()
                .find(|(k, _)| *k == name)
                .map(|(_, v)| std::ffi::OsString::from(v))
        }
    };
    let folder = |pairs| user_folder("remesh", env(pairs));
    assert_eq!(
        folder(&[("HOME", "/home/u")]),
        Some(PathBuf::from("/home/u/.cache/anthesis/remesh"))
    );
    assert_eq!(
        folder(&[("HOME", "/home/u"), ("XDG_CACHE_HOME", "/var/c")]),
        Some(PathBuf::from("/var/c/anthesis/remesh"))
    );
    // A relative XDG_CACHE_HOME is ignored, as the specification says.
    assert_eq!(
        folder(&[("HOME", "/home/u"), ("XDG_CACHE_HOME", "rel")]),
        Some(PathBuf::from("/home/u/.cache/anthesis/remesh"))
    );
    assert_eq!(
        folder(&[
            ("HOME", "/home/u"),
            ("XDG_CACHE_HOME", "/var/c"),
            (CACHE_DIR_VARIABLE, "/tmp/mine")
        ]),
        Some(PathBuf::from("/tmp/mine/remesh"))
    );
    // Set and empty: off.
    assert_eq!(
        folder(&[("HOME", "/home/u"), (CACHE_DIR_VARIABLE, "")]),
        None
    );
    assert_eq!(folder(&[]), None);
}

#[test]
fn keys_keep_their_fields_apart() {
    let of = |parts: &[&[u8]]| {
        let mut hasher = KeyHasher::new("test");
        for part in parts {
            hasher.bytes(part);
        }
        hasher.finish()
    };
    assert_ne!(of(&[b"ab", b"c"]), of(&[b"a", b"bc"]));
    assert_eq!(of(&[b"ab", b"c"]), of(&[b"ab", b"c"]));
    let float = |value: f64| {
        let mut hasher = KeyHasher::new("test");
        hasher.f64(value);
        hasher.finish()
    };
    assert_ne!(float(0.0), float(-0.0));
    assert_ne!(float(1.3), float(1.3f64.next_up()));
    let mut a = KeyHasher::new("one");
    a.u64(1);
    let mut b = KeyHasher::new("two");
    b.u64(1);
    assert_ne!(a.finish(), b.finish());
    let seq = |values: &[f64]| {
        let mut hasher = KeyHasher::new("test");
        hasher.f64s(values.iter().copied()).f64s([]);
        hasher.finish()
    };
    assert_ne!(seq(&[1.0, 2.0]), seq(&[1.0]));
}
