use super::*;
use crate::BaseRegion;
use anthesis_mesh::generate::test_petal;
use std::path::Path;

fn template() -> Template {
    crate::test_template("petal", test_petal(10.0, 5.0, 9, 17))
}

/// Whether two meshes are the same bit for bit (every float's bits, NaN
/// and -0.0 included, and the triangles): the binary layout keeps exactly
/// those.
fn same_bits(a: &Mesh, b: &Mesh) -> bool {
    mesh_to_bytes(a) == mesh_to_bytes(b)
}

fn entries(folder: &Path) -> Vec<std::path::PathBuf> {
    let mut found: Vec<_> = std::fs::read_dir(folder)
        .map(|listing| listing.map(|e| e.expect("entry").path()).collect())
        .unwrap_or_default();
    found.sort();
    found
}

const EDGE: f64 = 0.8;

#[test]
fn tests_run_without_the_user_cache() {
    // Nothing in the library's tests installs a cache, so `resolve` and
    // `remesh_template_cached` never write into the user's.
    assert_eq!(installed().folder(), None);
}

#[test]
fn a_hit_is_the_fresh_remesh_bit_for_bit() {
    let dir = tempfile::tempdir().expect("temp");
    let cache = Cache::in_folder(dir.path());
    let template = template();
    let fresh = remesh_template(&template, EDGE).expect("remeshes");
    let (first, outcome) = remesh_template_in(&template, EDGE, &cache).expect("remeshes");
    assert_eq!(outcome, Outcome::Miss);
    assert!(same_bits(&first, &fresh));
    assert_eq!(entries(dir.path()).len(), 1);
    // Another process (another Cache value on the folder) hits.
    let again = Cache::in_folder(dir.path());
    let (hit, outcome) = remesh_template_in(&template, EDGE, &again).expect("reads");
    assert_eq!(outcome, Outcome::Hit);
    assert!(same_bits(&hit, &fresh));
    assert_eq!(entries(dir.path()).len(), 1);
}

#[test]
fn any_change_of_what_the_remesh_depends_on_is_a_miss() {
    let dir = tempfile::tempdir().expect("temp");
    let cache = Cache::in_folder(dir.path());
    let template = template();
    remesh_template_in(&template, EDGE, &cache).expect("remeshes");
    let mut changed: Vec<(&str, Template, f64)> = Vec::new();
    let mut moved = template.clone();
    moved.mesh.positions[40].y = moved.mesh.positions[40].y.next_up();
    changed.push(("a position's last bit", moved, EDGE));
    let mut uv = template.clone();
    uv.mesh.uvs[40].x = uv.mesh.uvs[40].x.next_down();
    changed.push(("a UV's last bit", uv, EDGE));
    let mut wound = template.clone();
    wound.mesh.triangles[0].rotate_left(1);
    changed.push(("a triangle's corners turned", wound, EDGE));
    let mut region = template.clone();
    region.base_region = BaseRegion {
        v_max: region.base_region.v_max.next_up(),
        ..region.base_region
    };
    changed.push(("the base region", region, EDGE));
    changed.push(("the edge's last bit", template.clone(), EDGE.next_up()));
    let base_key = remesh_key(&template, EDGE);
    for (what, template, edge) in changed {
        let key = remesh_key(&template, edge);
        assert_ne!(key, base_key, "{what}");
        let fresh = remesh_template(&template, edge).expect("remeshes");
        let (mesh, outcome) = remesh_template_in(&template, edge, &cache).expect("remeshes");
        assert_eq!(outcome, Outcome::Miss, "{what}");
        assert!(same_bits(&mesh, &fresh), "{what}");
    }
    // Another remesher version is another key, a miss.
    let next = key_at_version(&template, EDGE, anthesis_bud::REMESH_VERSION + 1);
    assert_ne!(next, base_key);
    let (_, outcome) = cache_with_key(&template, EDGE, &cache, &next).expect("remeshes");
    assert_eq!(outcome, Outcome::Miss);
    // What does not change the result (the name, the maps) is a hit.
    let mut renamed = template.clone();
    renamed.name = "other".to_string();
    renamed.dg *= 2.0;
    assert_eq!(remesh_key(&renamed, EDGE), base_key);
}

#[test]
fn damaged_entries_are_misses_and_are_replaced() {
    let dir = tempfile::tempdir().expect("temp");
    let cache = Cache::in_folder(dir.path());
    let template = template();
    let fresh = remesh_template(&template, EDGE).expect("remeshes");
    remesh_template_in(&template, EDGE, &cache).expect("remeshes");
    let path = cache.entry_path(&remesh_key(&template, EDGE)).expect("on");
    let good = std::fs::read(&path).expect("written");
    let key = remesh_key(&template, EDGE);
    // A valid entry whose payload is a mesh of another layout version:
    // the container is fine, the mesh reader refuses it.
    let mut payload = mesh_to_bytes(&fresh);
    payload[4] ^= 0xff;
    let foreign_mesh = Cache::in_folder(dir.path().join("scratch"));
    foreign_mesh.put(&key, &payload);
    let foreign_mesh = std::fs::read(foreign_mesh.entry_path(&key).expect("on")).expect("read");
    let damaged: Vec<(&str, Vec<u8>)> = vec![
        ("truncated", good[..good.len() / 2].to_vec()),
        ("empty", Vec::new()),
        ("a flipped bit", {
            let mut bytes = good.clone();
            let at = bytes.len() - 100;
            bytes[at] ^= 1;
            bytes
        }),
        ("a foreign cache version", {
            let mut bytes = good.clone();
            bytes[8] ^= 0x7f;
            bytes
        }),
        ("a foreign mesh version", foreign_mesh),
    ];
    for (what, bytes) in damaged {
        std::fs::write(&path, &bytes).expect("damaged");
        let (mesh, outcome) = remesh_template_in(&template, EDGE, &cache).expect("remeshes");
        assert_eq!(outcome, Outcome::Miss, "{what}");
        assert!(same_bits(&mesh, &fresh), "{what}");
        assert_eq!(std::fs::read(&path).expect("rewritten"), good, "{what}");
        let (_, outcome) = remesh_template_in(&template, EDGE, &cache).expect("reads");
        assert_eq!(outcome, Outcome::Hit, "{what}: replaced by a valid entry");
    }
}

#[test]
fn an_unwritable_cache_remeshes_and_warns_once() {
    let dir = tempfile::tempdir().expect("temp");
    let file = dir.path().join("file");
    std::fs::write(&file, b"x").expect("written");
    let cache = Cache::in_folder(file.join("remesh"));
    let template = template();
    let fresh = remesh_template(&template, EDGE).expect("remeshes");
    for _ in 0..2 {
        let (mesh, outcome) = remesh_template_in(&template, EDGE, &cache).expect("remeshes");
        assert_eq!(outcome, Outcome::Miss);
        assert!(same_bits(&mesh, &fresh));
    }
    assert!(cache.take_warning().is_some());
    assert_eq!(cache.take_warning(), None);
}

#[test]
fn failures_are_not_kept() {
    let dir = tempfile::tempdir().expect("temp");
    let cache = Cache::in_folder(dir.path());
    let template = template();
    for _ in 0..2 {
        let error = remesh_template_in(&template, 1000.0, &cache).expect_err("too coarse");
        assert_eq!(Err(error), remesh_template(&template, 1000.0));
    }
    assert!(entries(dir.path()).is_empty());
}

#[test]
fn concurrent_remeshes_agree_and_leave_one_valid_entry() {
    let dir = tempfile::tempdir().expect("temp");
    let template = template();
    let fresh = remesh_template(&template, EDGE).expect("remeshes");
    let meshes: Vec<Mesh> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..4)
            .map(|i| {
                let (folder, template) = (dir.path(), &template);
                std::thread::Builder::new()
                    .name(format!("remesh-cache-test-{i}"))
                    .spawn_scoped(scope, move || {
                        let cache = Cache::in_folder(folder);
                        remesh_template_in(template, EDGE, &cache)
                            .expect("remeshes")
                            .0
                    })
                    .expect("thread")
            })
            .collect();
        workers
            .into_iter()
            .map(|w| w.join().expect("joined"))
            .collect()
    });
    for mesh in &meshes {
        assert!(same_bits(mesh, &fresh));
    }
    assert_eq!(entries(dir.path()).len(), 1, "{:?}", entries(dir.path()));
    let (_, outcome) =
        remesh_template_in(&template, EDGE, &Cache::in_folder(dir.path())).expect("reads");
    assert_eq!(outcome, Outcome::Hit);
}

/// The digest of one remesh made with the remesher at
/// [`anthesis_bud::REMESH_VERSION`]. When this test fails, the remesher's
/// output changed: bump `REMESH_VERSION` (so caches miss instead of serving
/// the old meshes) and record the new digest with the new version here.
#[test]
fn a_changed_remesher_must_bump_its_version() {
    const DIGESTS: [(u32, &str); 1] = [(
        1,
        "33b4b35990b3831c7ffbcb9c9f5a77d2f258f16511cc8e4582851d6b756dc962",
    )];
    let mesh = remesh_template(&template(), EDGE).expect("remeshes");
    let mut digest = KeyHasher::new("remesher output");
    digest.bytes(&mesh_to_bytes(&mesh));
    let digest = digest.finish().hex();
    let recorded = DIGESTS
        .iter()
        .find(|(version, _)| *version == anthesis_bud::REMESH_VERSION)
        .map(|(_, digest)| *digest);
    assert_eq!(
        recorded,
        Some(digest.as_str()),
        "the remesher's output changed: bump anthesis_bud::REMESH_VERSION and record \
         ({}, \"{digest}\") here",
        anthesis_bud::REMESH_VERSION + 1
    );
}
