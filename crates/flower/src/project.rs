//! The project file format (being written).
