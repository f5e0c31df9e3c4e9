//! Embeds the default flowers: lists every file under
//! `assets/flowers/<name>/` of the workspace into `$OUT_DIR/builtin_files.rs`
//! as `include_bytes!` entries, so the binary carries the committed projects
//! and needs no `assets/` folder beside it.

use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};

fn files_under(folder: &Path, relative: &str, out: &mut Vec<(String, PathBuf)>) {
    let Ok(entries) = fs::read_dir(folder) else {
        return;
    };
    let mut entries: Vec<_> = entries.filter_map(Result::ok).collect();
    entries.sort_by_key(|e| e.file_name());
    for entry in entries {
        let name = entry.file_name().to_string_lossy().into_owned();
        let path = entry.path();
        let inside = if relative.is_empty() {
            name.clone()
        } else {
            format!("{relative}/{name}")
        };
        if path.is_dir() {
            files_under(&path, &inside, out);
        } else {
            out.push((inside, path));
        }
    }
}

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap_or_default());
    let flowers = manifest.join("../../assets/flowers");
    println!("cargo:rerun-if-changed={}", flowers.display());
    let mut code = String::from(
        "/// Files of each embedded flower: (flower name, [(path in its folder, bytes)]).\n\
         pub(crate) static BUILTIN_FILES: &[(&str, &[EmbeddedFile])] = &[\n",
    );
    let mut names: Vec<_> = fs::read_dir(&flowers)
        .map(|entries| {
            entries
                .filter_map(Result::ok)
                .filter(|e| e.path().is_dir())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    for name in names {
        let mut files = Vec::new();
        files_under(&flowers.join(&name), "", &mut files);
        let _ = writeln!(code, "    ({name:?}, &[");
        for (relative, path) in files {
            println!("cargo:rerun-if-changed={}", path.display());
            let _ = writeln!(
                code,
                "        ({relative:?}, include_bytes!({:?})),",
                path.display().to_string()
            );
        }
        let _ = writeln!(code, "    ]),");
    }
    code.push_str("];\n");
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap_or_default()).join("builtin_files.rs");
    if let Err(error) = fs::write(&out, code) {
        panic!("cannot write {}: {error}", out.display());
    }
}
