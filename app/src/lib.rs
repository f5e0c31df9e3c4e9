//! The Anthesis application: the desktop window ([`desktop`]) and the
//! command line ([`cli`]) over the engine crates.

pub mod animation;
pub mod cli;
pub mod desktop;
pub mod look;
pub mod parts;
pub mod thumbnail;
