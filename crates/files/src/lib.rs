//! Files that may come from someone else, and the rules for reading them
//! ([`read`]): only regular files within a size limit, paths a project
//! names confined to its folder, and at most a short escaped excerpt of a
//! file's content in a message. Writing the files Anthesis saves so that
//! nothing is lost ([`write`]): the one atomic writer. Results kept between
//! runs under the hash of what they were made from ([`cache`]).

#![warn(missing_docs)]

pub mod cache;
pub mod read;
pub mod write;

pub use read::{
    FileError, check_relative, excerpt, human_bytes, read_regular, read_regular_text,
    resolve_inside, short_number,
};
pub use write::{
    WriteError, check_destination, create_folder, folder_of, write_atomic, write_atomic_with,
};
