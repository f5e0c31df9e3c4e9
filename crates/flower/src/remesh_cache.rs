//! Remeshed templates kept between runs: [`remesh_template`] is a pure
//! function of the template's mesh, its base region and the edge, and
//! takes a noticeable part of a short run's start-up (the lily at Table 1's
//! edge: about a third of a second of a one-second run), so its results
//! are kept in a content-addressed [`Cache`] (`anthesis_files::cache`:
//! SHA-256 keys, checked entries, atomic writes, a size bound).
//!
//! The key ([`remesh_key`]) holds everything the result depends on: the
//! template's mesh (positions, UVs and triangles, bit for bit), its base
//! region, the edge's bits, every field of the remesh options, the base
//! particle minimum the result is checked against,
//! [`anthesis_bud::REMESH_VERSION`] (bumped whenever the remesher's output
//! changes) and [`ENTRY_VERSION`] (this module's key and payload). The
//! payload is the mesh in `anthesis_mesh::binary`'s layout, so a hit is the
//! same mesh bit for bit. Only meshes are kept: a template that cannot be
//! remeshed is tried again each time and gives the same error.
//!
//! Which cache: [`remesh_template_in`] takes one; [`remesh_template_cached`]
//! (and so [`resolve`](crate::resolution::resolve)) uses the one the
//! program [`install`]ed at start-up, or none. Only the `anthesis` binary
//! installs one (the user's, [`Cache::user`] with [`FOLDER`]); libraries,
//! tests and examples that do not install one never write a cache.

use std::sync::OnceLock;

/// The cache and what a lookup found, for callers of this module.
pub use anthesis_files::cache::{Cache, Outcome};
use anthesis_files::cache::{Key, KeyHasher};
use anthesis_mesh::Mesh;
use anthesis_mesh::binary::{mesh_from_bytes, mesh_to_bytes};

use crate::resolution::{ResolutionError, options, remesh_template};
use crate::{MIN_BASE_PARTICLES, Template};

/// The user cache's subfolder for remeshed templates
/// (`~/.cache/anthesis/remesh`).
pub const FOLDER: &str = "remesh";

/// The version of how this module makes keys and payloads; bump it when a
/// field is added to the key or the payload's meaning changes (the
/// remesher's own changes bump [`anthesis_bud::REMESH_VERSION`]).
pub const ENTRY_VERSION: u32 = 1;

/// The cache [`install`]ed for this process, if any.
static INSTALLED: OnceLock<Cache> = OnceLock::new();

/// The cache used when none was installed: off.
static OFF: Cache = Cache::off();

/// Makes `cache` the one [`remesh_template_cached`] uses for the rest of
/// the process. Only the first call counts (a later one returns `false`
/// and changes nothing), so a program calls it once, at start-up.
pub fn install(cache: Cache) -> bool {
    INSTALLED.set(cache).is_ok()
}

/// The installed cache, or one that is off.
pub fn installed() -> &'static Cache {
    INSTALLED.get().unwrap_or(&OFF)
}

/// The key of `template` remeshed at `mean_edge` (see the module
/// documentation).
pub fn remesh_key(template: &Template, mean_edge: f64) -> Key {
    key_at_version(template, mean_edge, anthesis_bud::REMESH_VERSION)
}

/// [`remesh_key`] as it would be with the remesher at `remesher_version`.
fn key_at_version(template: &Template, mean_edge: f64, remesher_version: u32) -> Key {
    let mesh = &template.mesh;
    let options = options(mean_edge);
    let region = template.base_region;
    let inner_side = match options.inner_side {
        anthesis_bud::InnerSide::Auto => 0,
        anthesis_bud::InnerSide::AlongSurfaceNormal => 1,
        anthesis_bud::InnerSide::AgainstSurfaceNormal => 2,
    };
    let mut key = KeyHasher::new("anthesis_flower::resolution::remesh_template");
    key.u64(u64::from(ENTRY_VERSION))
        .u64(u64::from(remesher_version))
        .f64s(mesh.positions.iter().flat_map(|p| p.to_array()))
        .f64s(mesh.uvs.iter().flat_map(|uv| uv.to_array()))
        .u32s(mesh.triangles.iter().flatten().copied())
        .f64(region.v_max)
        .f64(region.u_min)
        .f64(region.u_max)
        .f64(mean_edge)
        .f64(options.target_edge)
        .u64(options.smoothing_iterations as u64)
        .f64(options.min_angle_floor_deg)
        .u64(options.max_vertices as u64)
        .u64(inner_side)
        .u64(u64::from(options.check_self_intersection))
        .u64(MIN_BASE_PARTICLES as u64);
    key.finish()
}

/// [`remesh_template`] through `cache`: the mesh kept under its key when
/// there is a valid one, else remeshed (and kept). Says whether it was a
/// hit. The mesh is the same, bit for bit, either way.
pub fn remesh_template_in(
    template: &Template,
    mean_edge: f64,
    cache: &Cache,
) -> Result<(Mesh, Outcome), ResolutionError> {
    cache_with_key(template, mean_edge, cache, &remesh_key(template, mean_edge))
}

fn cache_with_key(
    template: &Template,
    mean_edge: f64,
    cache: &Cache,
    key: &Key,
) -> Result<(Mesh, Outcome), ResolutionError> {
    cache.get_or_make(
        key,
        |bytes| mesh_from_bytes(bytes).ok(),
        || remesh_template(template, mean_edge),
        mesh_to_bytes,
    )
}

/// [`remesh_template`] through the [`install`]ed cache (none: remeshed
/// every time). What the window and the command line call.
pub fn remesh_template_cached(
    template: &Template,
    mean_edge: f64,
) -> Result<Mesh, ResolutionError> {
    remesh_template_in(template, mean_edge, installed()).map(|(mesh, _)| mesh)
}

#[cfg(test)]
mod tests;
