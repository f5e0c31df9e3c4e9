//! Files that may come from someone else, and the rules for reading them
//! ([`read`]): only regular files within a size limit, paths a project
//! names confined to its folder, and at most a short escaped excerpt of a
//! file's content in a message.

pub mod read;

pub use read::{
    FileError, check_relative, excerpt, human_bytes, read_regular, read_regular_text,
    resolve_inside,
};
