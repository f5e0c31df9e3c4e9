//! Wavefront OBJ import and export (being written).
