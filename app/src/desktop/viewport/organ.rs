//! One organ as the viewport displays it: the type the scene builds and the
//! fields drawn on it read, kept apart so neither module needs the other.

use glam::{DVec2, DVec3};

/// One organ as displayed.
#[derive(Debug, Clone)]
pub struct SceneOrgan {
    /// Index into the project's organs.
    pub organ: usize,
    pub positions_in_world: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    pub uvs: Vec<DVec2>,
    /// Simulated in the current run (false: shown in its bud state).
    pub simulated: bool,
}
