//! Mesh validation (being written).
