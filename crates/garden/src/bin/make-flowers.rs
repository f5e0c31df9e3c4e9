//! Writes the default flowers to `assets/flowers/<name>/<name>.anthesis.toml`
//! (with their meshes and maps beside them) from the builders in
//! `anthesis_garden::flowers`.
//!
//! `cargo run -p anthesis-garden --bin make-flowers [-- OUT_FOLDER]`
//! (default: the workspace's `assets/flowers`).

use std::path::PathBuf;
use std::process::ExitCode;

use anthesis_flower::project::save_project;
use anthesis_garden::{FLOWER_NAMES, flowers, project_file_name};

fn main() -> ExitCode {
    let out = std::env::args_os().nth(1).map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/flowers"),
        PathBuf::from,
    );
    let out = std::fs::canonicalize(&out).unwrap_or(out);
    for name in FLOWER_NAMES {
        let project = match flowers::flower(name) {
            Some(Ok(project)) => project,
            Some(Err(error)) => {
                eprintln!("make-flowers: {name}: {error}");
                return ExitCode::FAILURE;
            }
            None => {
                eprintln!("make-flowers: no builder for {name}");
                return ExitCode::FAILURE;
            }
        };
        // Start from an empty folder: saving leaves files the new project no
        // longer names, and everything in the folder gets embedded.
        let folder = out.join(name);
        if folder.exists()
            && let Err(error) = std::fs::remove_dir_all(&folder)
        {
            eprintln!("make-flowers: cannot clear {}: {error}", folder.display());
            return ExitCode::FAILURE;
        }
        let path = folder.join(project_file_name(name));
        if let Err(error) = save_project(&project, &path) {
            eprintln!("make-flowers: {error}");
            return ExitCode::FAILURE;
        }
        println!("wrote {}", path.display());
    }
    ExitCode::SUCCESS
}
