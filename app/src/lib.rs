//! The Anthesis application: for now the command line over the engine; the
//! desktop window comes with the "desktop app" issue.

pub mod cli;
