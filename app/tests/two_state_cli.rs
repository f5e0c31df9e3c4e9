//! `anthesis simulate` of a saved project with a two-state template (issue
//! 15 item 1): the file written with its open shape, read back, run, and
//! exported; the two-state organ's last keyframe is its open shape, placed.

use std::path::Path;

mod common;

use anthesis_flower::{TwoStateAnimation, joint_angle_after};
use common::{anthesis, text};
use glam::DQuat;

const KEYFRAMES: u32 = 6;

/// The two-organ whorl with the sepal template opening by two states:
/// its bud curled outwards towards the tip.
fn saved(dir: &Path) -> (std::path::PathBuf, anthesis_flower::Project) {
    let mut project = anthesis_sim::fixtures::whorl(2, 8, 14, KEYFRAMES);
    let sepal = &mut project.flower.templates[1];
    let open = sepal
        .mesh
        .positions
        .iter()
        .zip(&sepal.mesh.uvs)
        .map(|(p, uv)| DQuat::from_rotation_x(0.4 * uv.y * uv.y) * *p)
        .collect();
    sepal.two_state = Some(TwoStateAnimation::new(open, KEYFRAMES));
    let path = dir.join("two-state.anthesis.toml");
    anthesis_flower::project::save_project(&project, &path).expect("save");
    (path, project)
}

#[test]
fn simulate_runs_a_two_state_organ_to_its_open_shape_and_exports_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (path, project) = saved(dir.path());
    assert!(dir.path().join("meshes/sepal.open.obj").is_file());

    // One OBJ per keyframe for the two-state organ.
    let objs = dir.path().join("objs");
    let out = anthesis(&[
        "simulate",
        path.to_str().expect("utf-8"),
        "--organ",
        "sepal-1",
        "--out",
        objs.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let mut files: Vec<_> = std::fs::read_dir(&objs)
        .expect("list")
        .map(|e| e.expect("entry").path())
        .collect();
    files.sort();
    assert_eq!(files.len(), KEYFRAMES as usize + 1, "bud + keyframes");
    let last_text = std::fs::read_to_string(&files[files.len() - 1]).expect("read");
    let last = anthesis_mesh::obj::parse_obj(
        &anthesis_mesh::obj::object_text(&last_text, Some("sepal-1")).expect("object"),
    )
    .expect("an OBJ");
    let sepal = &project.flower.templates[1];
    let placement = project.flower.organs[1].placement;
    let extra = joint_angle_after(&sepal.joint_schedule, KEYFRAMES);
    let open = &sepal.two_state.as_ref().expect("two-state").open;
    let miss = last
        .positions
        .iter()
        .zip(open)
        .map(|(got, p)| got.distance(placement.world_from_template(*p, extra)))
        .fold(0.0, f64::max);
    let length = anthesis_flower::scale::organ_length(&sepal.mesh);
    // The OBJ's printed digits bound the agreement.
    assert!(miss < 1e-5 * length, "{miss} from the open shape");
    let bud_tip_moved = last
        .positions
        .iter()
        .zip(&sepal.mesh.positions)
        .map(|(got, p)| got.distance(placement.world_from_template(*p, extra)))
        .fold(0.0, f64::max);
    assert!(bud_tip_moved > 0.1 * length, "it opened by {bud_tip_moved}");

    // Both organs in a .glb.
    let glb = dir.path().join("out.glb");
    let out = anthesis(&[
        "simulate",
        path.to_str().expect("utf-8"),
        "--out",
        glb.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let bytes = std::fs::read(&glb).expect("glb written");
    assert_eq!(&bytes[..4], b"glTF");
    let json = String::from_utf8_lossy(&bytes);
    assert!(json.contains("\"sepal-1\"") && json.contains("\"petal-1\""));
}
