use std::collections::HashMap;

use super::*;

fn tube(length: f64, radius: f64, curvature_deg: f64) -> Tube {
    Tube {
        length,
        radius,
        curvature_deg,
    }
}

fn part(shape: PartShape, count: u32) -> Part {
    Part {
        name: shape.kind().to_string(),
        shape,
        count,
        ring_radius: 0.5,
        height: 0.2,
        offset_deg: 30.0,
        angle_deg: 10.0,
        schedule: Vec::new(),
        colour: [0.9, 0.9, 0.7, 1.0],
        head_colour: [0.6, 0.2, 0.05, 1.0],
    }
}

fn stamen() -> PartShape {
    PartShape::Stamen {
        filament: tube(8.0, 0.12, 30.0),
        anther_length: 1.5,
        anther_radius: 0.3,
        anther_tilt_deg: 90.0,
    }
}

fn pistil() -> PartShape {
    PartShape::Pistil {
        style: tube(9.0, 0.15, 10.0),
        stigma_radius: 0.4,
        stigma_lobes: 3,
        ovary_length: 2.0,
        ovary_radius: 0.45,
    }
}

/// Every edge of a closed surface wound consistently appears once in each
/// direction.
fn assert_closed_and_consistent(mesh: &Mesh, what: &str) {
    let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            *edges.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &edges {
        assert_eq!(n, 1, "{what}: edge {a}->{b} used {n} times");
        assert_eq!(
            edges.get(&(b, a)),
            Some(&1),
            "{what}: edge {a}->{b} has no opposite"
        );
    }
    assert_eq!(mesh.positions.len(), mesh.uvs.len());
    for uv in &mesh.uvs {
        assert!(
            (0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y),
            "{what}: uv {uv}"
        );
    }
}

/// Signed volume: positive for a closed surface wound around its outward
/// normal.
fn volume(mesh: &Mesh) -> f64 {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}

#[test]
fn every_part_mesh_is_closed_and_wound_outwards() {
    let receptacle = PartShape::Receptacle {
        radius: 2.0,
        depth: 1.0,
    };
    let pedicel = PartShape::Pedicel {
        stalk: tube(10.0, 0.3, -20.0),
    };
    for shape in [stamen(), pistil(), pedicel] {
        for (mesh, _, suffix) in part(shape, 1).meshes() {
            let what = format!("{}{suffix}", shape.kind());
            assert_closed_and_consistent(&mesh, &what);
            assert!(volume(&mesh) > 0.0, "{what} is wound inwards");
        }
    }
    // The receptacle keeps its seam (its own convention) but faces out.
    let (mesh, colour, _) = part(receptacle, 1).meshes().remove(0);
    assert!(volume(&mesh) > 0.0);
    assert_eq!(colour, [0.9, 0.9, 0.7, 1.0]);
}

#[test]
fn a_straight_tube_has_the_volume_of_its_polygon_prism() {
    let (length, radius) = (5.0, 0.2);
    let mesh = tube_mesh(&tube(length, radius, 0.0), (0.0, 1.0));
    // Ten-sided polygon: area = n/2 r² sin(2π/n).
    let polygon = 0.5 * AROUND as f64 * radius * radius * (TAU / AROUND as f64).sin();
    assert!((volume(&mesh) - polygon * length).abs() < 1e-12 * polygon * length);
    // Flat caps at both ends, v along it.
    let top = mesh.positions.iter().map(|p| p.y).fold(f64::MIN, f64::max);
    assert!((top - length).abs() < 1e-12);
    for (p, uv) in mesh.positions.iter().zip(&mesh.uvs) {
        assert!((uv.y - p.y / length).abs() < 1e-12);
    }
}

#[test]
fn a_tube_bends_outwards_along_a_circular_arc() {
    let t = tube(PI, 0.05, 90.0);
    // A quarter circle of radius 2 from the origin, leaving along +Y and
    // ending along +Z.
    let (tip, tangent) = t.centre_at(PI);
    assert!((tip - DVec3::new(0.0, 2.0, 2.0)).length() < 1e-12, "{tip}");
    assert!((tangent - DVec3::Z).length() < 1e-12);
    let (middle, _) = t.centre_at(0.5 * PI);
    let expected = DVec3::new(
        0.0,
        2.0 * (0.25 * PI).sin(),
        2.0 * (1.0 - (0.25 * PI).cos()),
    );
    assert!((middle - expected).length() < 1e-12);
    // Inward curvature mirrors it.
    let (tip, _) = tube(PI, 0.05, -90.0).centre_at(PI);
    assert!((tip - DVec3::new(0.0, 2.0, -2.0)).length() < 1e-12);
}

#[test]
fn the_anther_sits_on_the_filament_tip_across_it() {
    let meshes = part(stamen(), 1).meshes();
    let PartShape::Stamen { filament, .. } = stamen() else {
        unreachable!()
    };
    let (tip, tangent) = filament.centre_at(filament.length);
    let anther = &meshes[1].0;
    let nearest = anther
        .positions
        .iter()
        .map(|p| p.distance(tip))
        .fold(f64::MAX, f64::min);
    assert!(nearest < filament.radius, "anther {nearest} from the tip");
    // Its long axis (the poles: first and last vertex of the sweep) lies
    // across the filament's tip tangent.
    let axis = (anther.positions[anther.positions.len() - 1] - anther.positions[0]).normalize();
    assert!(axis.dot(tangent).abs() < 1e-9);
    assert!((anther.positions[0].distance(*anther.positions.last().unwrap()) - 1.5).abs() < 1e-9);
}

#[test]
fn instances_go_around_the_axis_and_a_schedule_turns_them_outwards() {
    let mut stamens = part(stamen(), 6);
    stamens.schedule = vec![JointRamp {
        from_step: 20,
        to_step: 80,
        angle_deg: 30.0,
    }];
    let placements = stamens.placements();
    assert_eq!(placements.len(), 6);
    for (k, p) in placements.iter().enumerate() {
        assert!((p.azimuth_deg - (30.0 + 60.0 * k as f64)).abs() < 1e-12);
        assert!((p.position.x.hypot(p.position.z) - 0.5).abs() < 1e-12);
        assert_eq!(p.position.y, 0.2);
    }
    assert_eq!(stamens.instance_name(2), "stamen-3");
    let flower = Flower {
        templates: Vec::new(),
        organs: Vec::new(),
        overlaps: Vec::new(),
        structure: None,
        parts: vec![stamens],
        unit: None,
    };
    let pieces = part_pieces(&flower);
    let names: Vec<&str> = pieces.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names[..3], ["receptacle", "stamen-1", "stamen-1-anther"]);
    assert_eq!(pieces.len(), 1 + 12);
    // The filament's base tangent (+Y in its frame) leans outwards from
    // the axis by the initial angle, then by 30° more once the ramp is done.
    let piece = &pieces[1];
    let lean = |step: u32| {
        let (_, rotation) = piece.pose(step);
        let up = rotation * DVec3::Y;
        let outwards =
            DVec3::new(piece.placement.position.x, 0.0, piece.placement.position.z).normalize();
        up.dot(outwards).atan2(up.y).to_degrees()
    };
    assert!((lean(0) - 10.0).abs() < 1e-9);
    assert!((lean(20) - 10.0).abs() < 1e-9);
    assert!((lean(50) - 25.0).abs() < 1e-9);
    assert!((lean(100) - 40.0).abs() < 1e-9);
    assert!(piece.moves());
    let moved = piece.positions_at(100);
    let (t, r) = piece.pose(100);
    assert_eq!(moved[7], t + r * piece.mesh.positions[7]);
}

#[test]
fn the_pedicel_points_down_and_a_receptacle_part_replaces_the_automatic_one() {
    let mut pedicel = part(
        PartShape::Pedicel {
            stalk: tube(10.0, 0.3, 0.0),
        },
        1,
    );
    pedicel.ring_radius = 0.0;
    pedicel.angle_deg = 0.0;
    pedicel.height = -1.0;
    let receptacle = part(
        PartShape::Receptacle {
            radius: 2.0,
            depth: 1.0,
        },
        1,
    );
    let flower = Flower {
        templates: Vec::new(),
        organs: Vec::new(),
        overlaps: Vec::new(),
        structure: None,
        parts: vec![receptacle, pedicel],
        unit: None,
    };
    let pieces = part_pieces(&flower);
    assert_eq!(pieces.len(), 2);
    assert_eq!(pieces[0].name, "receptacle");
    let lowest = pieces[1]
        .positions_at(0)
        .iter()
        .map(|p| p.y)
        .fold(f64::MAX, f64::min);
    assert!((lowest + 11.0).abs() < 1e-9, "{lowest}");
    // Only the pedicel keeps organs out.
    let obstacles = obstacles(&flower);
    assert_eq!(obstacles.len(), 1);
    assert_eq!(obstacles[0].name, "pedicel");
}

#[test]
fn each_closed_component_is_an_obstacle_of_its_own() {
    let flower = Flower {
        templates: Vec::new(),
        organs: Vec::new(),
        overlaps: Vec::new(),
        structure: None,
        parts: vec![part(pistil(), 1), part(stamen(), 2)],
        unit: None,
    };
    let obstacles = obstacles(&flower);
    // Style, ovary and three lobes; filament and anther twice.
    let names: Vec<&str> = obstacles.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "pistil", "pistil", "pistil", "pistil", "pistil", "stamen-1", "stamen-1", "stamen-2",
            "stamen-2"
        ]
    );
    for o in &obstacles {
        assert_closed_and_consistent(&o.mesh, &o.name);
        assert!(volume(&o.mesh) > 0.0);
    }
}

#[test]
fn bad_parameters_are_refused_naming_the_part() {
    let mut p = part(stamen(), 6);
    assert_eq!(p.check(), Ok(()));
    p.count = 0;
    assert_eq!(
        p.check().unwrap_err(),
        "stamen \"stamen\": count must be 1 to 64, not 0"
    );
    p.count = 6;
    p.shape = PartShape::Stamen {
        filament: tube(-1.0, 0.1, 0.0),
        anther_length: 1.0,
        anther_radius: 0.2,
        anther_tilt_deg: 0.0,
    };
    assert_eq!(
        p.check().unwrap_err(),
        "stamen \"stamen\": the filament's length must be a positive number, not -1"
    );
    let mut pistil = part(pistil(), 1);
    pistil.shape = PartShape::Pistil {
        style: tube(5.0, 0.1, 0.0),
        stigma_radius: 0.3,
        stigma_lobes: 0,
        ovary_length: 0.0,
        ovary_radius: 0.0,
    };
    assert!(
        pistil
            .check()
            .unwrap_err()
            .contains("stigma_lobes must be 1 to 8")
    );
    let mut receptacle = part(
        PartShape::Receptacle {
            radius: 1.0,
            depth: 1.0,
        },
        2,
    );
    assert!(receptacle.check().unwrap_err().contains("one receptacle"));
    receptacle.count = 1;
    receptacle.colour = [1.5, 0.0, 0.0, 1.0];
    assert!(receptacle.check().unwrap_err().contains("color components"));
}

#[test]
fn an_lsystems_f_segments_are_tubes_of_its_width_from_start_to_end() {
    use crate::structure::Structure;
    let flower = Flower {
        templates: Vec::new(),
        organs: Vec::new(),
        overlaps: Vec::new(),
        structure: Some(Structure::LSystem {
            text: "axiom: #(0.4) F(2) [ +(90) ;(1, 1, 0) F(1) ] !(0) F(3) #(0.2) f(1) F(1)"
                .to_string(),
            steps: 0,
            surfaces: Default::default(),
            units: 1.0,
        }),
        parts: Vec::new(),
        unit: None,
    };
    let pieces = part_pieces(&flower);
    let names: Vec<&str> = pieces.iter().map(|p| p.name.as_str()).collect();
    // The width-0 segment draws nothing.
    assert_eq!(names, ["receptacle", "segment-1", "segment-2", "segment-3"]);
    // Each tube's end caps are centred on the segment's ends: the pole
    // vertices of the sweep are its first and last.
    let ends = |piece: &PartPiece| {
        let p = piece.positions_at(0);
        (p[0], p[p.len() - 1])
    };
    let close = |a: DVec3, b: DVec3| (a - b).length() < 1e-12;
    let (start, end) = ends(&pieces[1]);
    assert!(
        close(start, DVec3::ZERO) && close(end, DVec3::new(0.0, 2.0, 0.0)),
        "{start} {end}"
    );
    // +(90) turns the heading H = +Y about U = +Z (R_U, eq. 1.2).
    let (start, end) = ends(&pieces[2]);
    assert!(close(start, DVec3::new(0.0, 2.0, 0.0)));
    assert!(
        ((end - start).length() - 1.0).abs() < 1e-12 && (end.y - 2.0).abs() < 1e-12,
        "{end}"
    );
    let (start, end) = ends(&pieces[3]);
    assert!(close(start, DVec3::new(0.0, 6.0, 0.0)) && close(end, DVec3::new(0.0, 7.0, 0.0)));
    // Radius: half the width.
    let radius = pieces[3].mesh.positions[1]
        .x
        .hypot(pieces[3].mesh.positions[1].z);
    assert!((radius - 0.1).abs() < 1e-12, "{radius}");
    for piece in &pieces[1..] {
        assert!(volume(&piece.mesh) > 0.0);
        assert!(!piece.moves());
    }
    // The branch is drawn in the colour `;` set, the others in the stem's.
    let colours: Vec<[f32; 4]> = pieces[1..].iter().map(|p| p.colour).collect();
    assert_eq!(
        colours,
        [RECEPTACLE_COLOUR, [1.0, 1.0, 0.0, 1.0], RECEPTACLE_COLOUR]
    );
    assert_eq!(obstacles(&flower).len(), 3, "the tubes keep organs out");
}

#[test]
fn a_tube_named_like_a_part_gets_a_free_name() {
    use crate::structure::Structure;
    let mut stem = part(
        PartShape::Pedicel {
            stalk: tube(4.0, 0.2, 0.0),
        },
        1,
    );
    stem.name = "stem".to_owned();
    let flower = Flower {
        templates: Vec::new(),
        organs: Vec::new(),
        overlaps: Vec::new(),
        structure: Some(Structure::LSystem {
            text: "name A = stem\naxiom: A\nA -> F(2)".to_string(),
            steps: 1,
            surfaces: Default::default(),
            units: 1.0,
        }),
        parts: vec![stem],
        unit: None,
    };
    let names: Vec<String> = part_pieces(&flower).into_iter().map(|p| p.name).collect();
    assert_eq!(names, ["receptacle", "stem", "stem-2"]);
}
