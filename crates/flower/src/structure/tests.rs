use glam::{DMat3, DVec3};

use super::lsystem::{LSystem, LSystemError, Module};
use super::turtle::{Defaults, Drawing, interpret, r_h, r_l, r_u};

fn word_text(word: &[Module]) -> String {
    word.iter()
        .map(|m| {
            if m.params.is_empty() {
                m.symbol.clone()
            } else {
                let p: Vec<String> = m.params.iter().map(|v| format!("{v}")).collect();
                format!("{}({})", m.symbol, p.join(","))
            }
        })
        .collect()
}

fn draw(text: &str, steps: u32) -> Drawing {
    let system = LSystem::parse(text).unwrap();
    interpret(&system.derive(steps).unwrap(), &Defaults::of(&system))
}

fn close(a: DVec3, b: DVec3) -> bool {
    (a - b).length() < 1e-12
}

#[test]
fn productions_are_applied_in_parallel() {
    // The Fibonacci words: every letter rewritten at once each step.
    let system = LSystem::parse("axiom: A\nA -> AB\nB -> A").unwrap();
    let words: Vec<String> = (0..=5)
        .map(|n| word_text(&system.derive(n).unwrap()))
        .collect();
    assert_eq!(
        words,
        ["A", "AB", "ABA", "ABAAB", "ABAABABA", "ABAABABAABAAB"]
    );
}

#[test]
fn parametric_productions_evaluate_their_parameters() {
    let system = LSystem::parse(
        "shrink = 0.5\n\
         axiom: A(1)\n\
         p1: A(x) -> F(x) [ +(30) A(x * shrink) ] A(2 * x - -1)",
    )
    .unwrap();
    assert_eq!(
        word_text(&system.derive(1).unwrap()),
        "F(1)[+(30)A(0.5)]A(3)"
    );
    assert_eq!(
        word_text(&system.derive(2).unwrap()),
        "F(1)[+(30)F(0.5)[+(30)A(0.25)]A(2)]F(3)[+(30)A(1.5)]A(7)"
    );
}

#[test]
fn the_turtle_starts_heading_up_with_left_towards_minus_x() {
    let d = draw("axiom: F(2) ~p", 0);
    assert!(close(d.segments[0].end, DVec3::new(0.0, 2.0, 0.0)));
    let p = &d.surfaces[0];
    assert_eq!(p.frame, DMat3::from_cols(DVec3::Y, -DVec3::X, DVec3::Z));
    // H × L = U.
    assert!(close(p.frame.x_axis.cross(p.frame.y_axis), p.frame.z_axis));
    // At the start the template frame is the world frame.
    assert_eq!(p.template_rotation(), DMat3::IDENTITY);
}

#[test]
fn every_rotation_symbol_turns_as_its_equation_says() {
    // Worked by hand from eqs. (1.1)–(1.4), starting at H = Y, L = -X, U = Z.
    // + (R_U): H' = cos a H - sin a L, L' = sin a H + cos a L.
    let d = draw("axiom: +(90) ~p", 0);
    let f = d.surfaces[0].frame;
    assert!(close(f.x_axis, DVec3::X) && close(f.y_axis, DVec3::Y) && close(f.z_axis, DVec3::Z));
    // & (R_L): H' = cos a H + sin a U, U' = -sin a H + cos a U.
    let f = draw("axiom: &(90) ~p", 0).surfaces[0].frame;
    assert!(close(f.x_axis, DVec3::Z) && close(f.y_axis, -DVec3::X) && close(f.z_axis, -DVec3::Y));
    // / (R_H): L' = cos a L + sin a U, U' = -sin a L + cos a U.
    let f = draw("axiom: /(90) ~p", 0).surfaces[0].frame;
    assert!(close(f.x_axis, DVec3::Y) && close(f.y_axis, DVec3::Z) && close(f.z_axis, DVec3::X));
    // The opposite symbols undo them, at any angle.
    for (a, b) in [("+", "-"), ("&", "^"), ("/", "\\")] {
        let f = draw(&format!("axiom: {a}(37) {b}(37) ~p"), 0).surfaces[0].frame;
        assert!(
            f.abs_diff_eq(DMat3::from_cols(DVec3::Y, -DVec3::X, DVec3::Z), 1e-12),
            "{a}{b}"
        );
    }
    // The matrices are rotations, and R(a) R(-a) = I.
    for r in [r_u(0.7), r_l(0.7), r_h(0.7)] {
        assert!((r.determinant() - 1.0).abs() < 1e-12);
        assert!((r * r.transpose()).abs_diff_eq(DMat3::IDENTITY, 1e-12));
    }
    assert!((r_u(0.3) * r_u(-0.3)).abs_diff_eq(DMat3::IDENTITY, 1e-12));
}

#[test]
fn parameterless_symbols_take_the_defaults() {
    let d = draw("angle = 90\nstep = 3\naxiom: + F", 0);
    assert!(close(d.segments[0].end, DVec3::new(3.0, 0.0, 0.0)));
    let d = draw("axiom: F f F", 0);
    assert!(close(d.segments[1].start, DVec3::new(0.0, 2.0, 0.0)));
    // Widths: set, increased and decreased by the increment.
    let d = draw(
        "initial line width = 20\nline width increment = 5\naxiom: F # F ! ! F #(7) F",
        0,
    );
    let widths: Vec<f64> = d.segments.iter().map(|s| s.width).collect();
    assert_eq!(widths, [20.0, 25.0, 15.0, 7.0]);
}

#[test]
fn brackets_nest_and_restore_position_frame_and_width() {
    let d = draw(
        "axiom: F(1) [ +(90) #(4) F(1) [ &(90) F(1) ] F(1) ] F(1)",
        0,
    );
    let ends: Vec<DVec3> = d.segments.iter().map(|s| s.end).collect();
    let want = [
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(1.0, 1.0, 1.0),
        DVec3::new(2.0, 1.0, 0.0),
        DVec3::new(0.0, 2.0, 0.0),
    ];
    for (got, want) in ends.iter().zip(want) {
        assert!(close(*got, want), "{ends:?}");
    }
    let widths: Vec<f64> = d.segments.iter().map(|s| s.width).collect();
    assert_eq!(widths, [1.0, 4.0, 4.0, 4.0, 1.0]);
}

#[test]
fn a_semicolon_sets_the_line_colour_and_brackets_restore_it() {
    let d = draw(
        "red = 1\naxiom: F ;(red, 0, 0) F [ ;(0, 2, -1) F ] F ; F ;(0.5) F",
        0,
    );
    let colours: Vec<Option<[f32; 4]>> = d.segments.iter().map(|s| s.colour).collect();
    assert_eq!(
        colours,
        [
            None,
            Some([1.0, 0.0, 0.0, 1.0]),
            // Clamped to [0, 1]; the bracket's colour ends with it.
            Some([0.0, 1.0, 0.0, 1.0]),
            Some([1.0, 0.0, 0.0, 1.0]),
            // `;` alone and `;` with fewer than three values: the default.
            None,
            None,
        ]
    );
}

/// The seed's apple flower, L-system (3), as written there.
const APPLE: &str = "\
initial line width = 20
line width increment = 5
lenA = 500
lenF = 100
ω :/(154) &(72) #A!B
p1:B → D/(60)D/(60)D/(60)D/(60)D/(60)D
p2:D → [C][P][S]
p3:A → F(lenA)
p4:C → ~c
p5:P → ~p
p6:S → F(lenF)[- (18)F(lenF)][+ (18)F(lenF)]
";

#[test]
fn the_apple_flower_of_the_seed_places_six_segments() {
    let system = LSystem::parse(APPLE).unwrap();
    let word = system.derive(3).unwrap();
    let d = interpret(&word, &Defaults::of(&system));
    let count = |x: char| d.surfaces.iter().filter(|s| s.surface == x).count();
    // Six segments of calyx, petal and stamen: 6 ~c, 6 ~p, and a stem plus
    // three lines per stamen.
    assert_eq!((count('c'), count('p')), (6, 6));
    assert_eq!(d.segments.len(), 1 + 6 * 3);
    // The stem: 500 long, width 20 + 5; the stamens after `!`: 20.
    let stem = &d.segments[0];
    assert!(((stem.end - stem.start).length() - 500.0).abs() < 1e-9);
    assert_eq!(stem.width, 25.0);
    assert!(d.segments[1..].iter().all(|s| s.width == 20.0));
    // Every organ sits at the stem's end; successive petals are 60° apart
    // about the heading.
    for s in &d.surfaces {
        assert!((s.position - stem.end).length() < 1e-9);
    }
    let petals: Vec<_> = d.surfaces.iter().filter(|s| s.surface == 'p').collect();
    for pair in petals.windows(2) {
        let (a, b) = (pair[0].frame, pair[1].frame);
        assert!((a.x_axis - b.x_axis).length() < 1e-9, "same heading");
        let cos = a.y_axis.dot(b.y_axis);
        assert!((cos - 60f64.to_radians().cos()).abs() < 1e-9, "{cos}");
    }
    // A stamen's two side lines leave its tip 18° either side of it.
    let (main, left, right) = (&d.segments[1], &d.segments[2], &d.segments[3]);
    let axis = (main.end - main.start).normalize();
    for side in [left, right] {
        assert!((side.start - main.end).length() < 1e-9);
        let angle = axis
            .dot((side.end - side.start).normalize())
            .acos()
            .to_degrees();
        assert!((angle - 18.0).abs() < 1e-9, "{angle}");
    }
}

#[test]
fn syntax_errors_name_the_line_the_column_and_what_was_expected() {
    let err = LSystem::parse("axiom: A\nA -> F(1 B").unwrap_err();
    assert_eq!(
        err,
        LSystemError::Syntax {
            line: 2,
            column: 10,
            expected: "`,`, `)` or an operator".into(),
            found: "`B`".into()
        }
    );
    let err = LSystem::parse("axiom: F ~(2)").unwrap_err();
    assert!(
        matches!(&err, LSystemError::Syntax { line: 1, column: 11, expected, .. } if expected.contains("surface")),
        "{err}"
    );
    let err = LSystem::parse("axiom: A\nB D").unwrap_err();
    assert!(matches!(err, LSystemError::Syntax { line: 2, .. }), "{err}");
    assert!(err.to_string().contains("expected `->`"), "{err}");
    let err = LSystem::parse("axiom: A\nA -> F(len)").unwrap_err();
    assert_eq!(
        err,
        LSystemError::UnknownName {
            line: 2,
            name: "len".into()
        }
    );
    let err = LSystem::parse("A -> B").unwrap_err();
    assert!(err.to_string().contains("no axiom"), "{err}");
    let err = LSystem::parse("axiom: A\nA(x, y) -> B(x)\naxiom: B").unwrap_err();
    assert!(err.to_string().contains("second axiom on line 3"), "{err}");
    // A module with fewer parameters than its production names.
    let system = LSystem::parse("axiom: A(1)\nA(x, y) -> B(x)").unwrap();
    assert!(matches!(
        system.derive(1).unwrap_err(),
        LSystemError::Arity {
            given: 1,
            needed: 2,
            line: 2,
            ..
        }
    ));
    // Exponential growth is stopped, not run out of memory.
    let system = LSystem::parse("axiom: A\nA -> AA").unwrap();
    assert!(matches!(
        system.derive(40).unwrap_err(),
        LSystemError::TooLong { step: 20 }
    ));
}

// ------------------------------------------------- bounds (issue 38)

use super::whorl::{Spiral, Whorl, nested_whorls, spiral};
use super::{MAX_STRUCTURE_ORGANS, Structure, StructureError};
use crate::Overlap;

/// The rules of nested whorls as every pair was once looked at.
fn nested_pairs_by_brute_force(whorls: &[Whorl]) -> Vec<Overlap> {
    let mut first = 0;
    let firsts: Vec<usize> = whorls
        .iter()
        .map(|w| {
            let f = first;
            first += w.count;
            f
        })
        .collect();
    let mut out = Vec::new();
    for (i, inner) in whorls.iter().enumerate() {
        for (j, outer) in whorls.iter().enumerate().skip(i + 1) {
            for a in 0..inner.count {
                for b in 0..outer.count {
                    let d = super::whorl::angular_distance_deg(
                        inner.azimuth_deg(a),
                        outer.azimuth_deg(b),
                    );
                    if d < inner.half_span_deg + outer.half_span_deg {
                        out.push(Overlap {
                            inner: firsts[i] + a,
                            outer: firsts[j] + b,
                        });
                    }
                }
            }
        }
    }
    out
}

fn ring(name: &str, count: usize, offset_deg: f64, half_span_deg: f64) -> Whorl {
    Whorl {
        name: name.to_owned(),
        template: 0,
        count,
        offset_deg,
        radius: 1.0,
        height: 0.0,
        joint_angle_deg: 0.0,
        half_span_deg,
    }
}

#[test]
fn windowed_whorl_rules_are_the_rules_of_every_pair_in_the_same_order() {
    // Counts, offsets and spans from narrow to wider than the circle.
    for (n_in, n_out, offset, span_in, span_out) in [
        (3, 3, 60.0, 40.0, 45.0),
        (5, 5, 36.0, 30.0, 30.0),
        (7, 13, 11.3, 5.0, 9.0),
        (40, 17, -250.0, 2.0, 12.0),
        (6, 6, 0.0, 30.0, 30.0),
        (9, 4, 725.0, 100.0, 90.0),
        (1, 8, 0.0, 0.0, 22.5),
    ] {
        let whorls = [
            ring("in", n_in, 0.0, span_in),
            ring("mid", n_out, offset, span_out),
            ring("out", n_in + n_out, offset / 3.0, span_in),
        ];
        assert_eq!(
            nested_whorls(&whorls).overlaps,
            nested_pairs_by_brute_force(&whorls),
            "{n_in} {n_out} {offset} {span_in} {span_out}"
        );
    }
}

#[test]
fn windowed_spiral_rules_are_the_rules_of_every_pair_in_the_same_order() {
    for (count, divergence, half_span) in [
        (30, super::GOLDEN_ANGLE_DEG, 40.0),
        (200, super::GOLDEN_ANGLE_DEG, 7.5),
        (50, 90.0, 45.0),
        (50, 360.0, 1.0),
        (25, -100.0, 95.0),
    ] {
        let s = Spiral {
            name: "s".to_owned(),
            template: 0,
            count,
            divergence_deg: divergence,
            first_radius: 1.0,
            first_height: 0.0,
            radius_step: 0.0,
            height_step: 0.0,
            joint_angle_deg: 0.0,
            half_span_deg: half_span,
        };
        let azimuth = |k: usize| divergence * k as f64;
        let mut expected = Vec::new();
        for later in 0..count {
            for earlier in 0..later {
                if super::whorl::angular_distance_deg(azimuth(earlier), azimuth(later))
                    < 2.0 * half_span
                {
                    expected.push(Overlap {
                        inner: later,
                        outer: earlier,
                    });
                }
            }
        }
        assert_eq!(spiral(&s).overlaps, expected, "{count} {divergence}");
    }
}

fn test_templates() -> Vec<crate::Template> {
    vec![
        crate::test_template("a", anthesis_mesh::generate::test_petal(1.0, 0.5, 2, 3)),
        crate::test_template("b", anthesis_mesh::generate::test_petal(1.0, 0.5, 2, 3)),
    ]
}

fn lsystem(text: &str, steps: u32) -> Structure {
    Structure::LSystem {
        text: text.to_owned(),
        steps,
        surfaces: [('A', 0), ('B', 1)].into_iter().collect(),
        units: 1.0,
    }
}

#[test]
fn too_many_organs_are_refused_before_any_is_made() {
    // 2^14 = 16,384 organs from a few bytes.
    let doubling = lsystem("axiom: ~A f(10)\n~A -> ~A f(10) ~A", 14);
    assert_eq!(
        doubling.arrange(&test_templates()),
        Err(StructureError::TooManyOrgans { count: 16_384 })
    );
    let ring = Structure::Whorls {
        whorls: vec![ring("r", MAX_STRUCTURE_ORGANS + 1, 0.0, 1.0)],
        contorted: false,
    };
    assert!(matches!(
        ring.arrange(&test_templates()),
        Err(StructureError::TooManyOrgans { .. })
    ));
}

#[test]
fn lsystem_rules_pair_only_organs_within_reach() {
    // Two rows of A and B organs facing the same way, 100 apart along x:
    // each B lies inside the A beside it only (all pairs faced alike).
    let text = "axiom: ~A ~B -(90) f(100) +(90) ~A ~B -(90) f(100) +(90) ~A ~B";
    let arrangement = lsystem(text, 0).arrange(&test_templates()).unwrap();
    let pairs: Vec<(usize, usize)> = arrangement
        .overlaps
        .iter()
        .map(|o| (o.inner, o.outer))
        .collect();
    assert_eq!(pairs, [(1, 0), (3, 2), (5, 4)]);
    // All at one spot: every B inside every A, in order.
    let text = "axiom: ~A ~A ~B ~B";
    let arrangement = lsystem(text, 0).arrange(&test_templates()).unwrap();
    let pairs: Vec<(usize, usize)> = arrangement
        .overlaps
        .iter()
        .map(|o| (o.inner, o.outer))
        .collect();
    assert_eq!(pairs, [(2, 0), (2, 1), (3, 0), (3, 1)]);
}

#[test]
fn organs_piled_on_one_spot_are_refused_not_paired_forever() {
    // 2 x 4096 organs at the origin: 16.7 million pairs within reach.
    let piled = lsystem("axiom: ~A ~B\n~A -> ~A ~A\n~B -> ~B ~B", 12);
    assert!(matches!(
        piled.arrange(&test_templates()),
        Err(StructureError::TooManyOverlaps { .. })
    ));
}

#[test]
fn a_parameter_that_is_not_finite_is_refused_with_line_and_column() {
    let error = LSystem::parse("axiom: F\n\nA -> +(0/0) F").unwrap_err();
    assert_eq!(
        error.to_string(),
        "L-system line 3, column 8: `0/0` is NaN, not a finite number"
    );
    let error = LSystem::parse("axiom: +(1/0)F").unwrap_err();
    assert_eq!(
        error.to_string(),
        "L-system line 1, column 10: `1/0` is inf, not a finite number"
    );
    let error = LSystem::parse("angle = NaN\naxiom: F").unwrap_err();
    assert!(matches!(
        error,
        LSystemError::NotFinite {
            line: 1,
            column: 9,
            ..
        }
    ));
    // Known only when derived: named with its production and step.
    let system = LSystem::parse("axiom: A(1)\nA(x) -> A(x / 0)").unwrap();
    assert_eq!(
        system.derive(2).unwrap_err().to_string(),
        "L-system line 2: the production gives module A the parameter inf at derivation step 1, not a finite number"
    );
}

#[test]
fn a_deeply_nested_expression_is_refused_not_a_stack_overflow() {
    let deep = format!("axiom: F({}1{})", "(".repeat(100_000), ")".repeat(100_000));
    assert!(matches!(
        LSystem::parse(&deep),
        Err(LSystemError::TooComplex {
            line: 1,
            column: 10
        })
    ));
    let long = format!("axiom: F({})", vec!["1"; 100_000].join("+"));
    assert!(matches!(
        LSystem::parse(&long),
        Err(LSystemError::TooComplex { .. })
    ));
}

fn tube_names(text: &str, steps: u32) -> Vec<String> {
    let structure = super::Structure::LSystem {
        text: text.to_owned(),
        steps,
        surfaces: Default::default(),
        units: 1.0,
    };
    structure
        .tubes()
        .into_iter()
        .map(|(name, _)| name)
        .collect()
}

#[test]
fn tubes_are_named_after_the_nearest_named_module_they_derive_from() {
    // The apple's stem and stamens, named: a name one tube has stays bare,
    // one several share is numbered in the word's order.
    let named = format!("{APPLE}name A = stem\nname S = stamen\n");
    let names = tube_names(&named, 3);
    let mut expected = vec!["stem".to_owned()];
    expected.extend((1..=18).map(|k| format!("stamen-{k}")));
    assert_eq!(names, expected);
    // The same text gives the same names every time.
    assert_eq!(tube_names(&named, 3), names);
    // Without names: the letter of the module whose production wrote the
    // `F`; the axiom's own `F` is a segment.
    assert_eq!(
        tube_names("axiom: F(1) A B\nA -> F(1)\nB -> F(1) F(1)", 1),
        ["segment", "A", "B-1", "B-2"]
    );
    // The nearest named module counts, not the last production: `F → F F`
    // rewrites every `F`, but the stem's pieces are still the stem's, and
    // those of the `F` an unnamed `S` inside a named `D` wrote the `D`'s.
    assert_eq!(
        tube_names(
            "name A = stem\nname D = whorl\naxiom: A D\nA -> F(1)\nF -> F(1) F(1)\nD -> S\nS -> F(1)",
            3
        ),
        ["stem-1", "stem-2", "stem-3", "stem-4", "whorl-1", "whorl-2"]
    );
    // A stamen's `F` named inside a named flower: the nearer name wins.
    assert_eq!(
        tube_names(
            "name B = flower\nname S = stamen\naxiom: B\nB -> F(1) S\nS -> F(1)",
            2
        ),
        ["flower", "stamen"]
    );
}

#[test]
fn a_name_statement_is_checked() {
    let err = LSystem::parse("name S = 3stamen\naxiom: S").unwrap_err();
    assert!(
        matches!(
            &err,
            LSystemError::Syntax {
                line: 1,
                column: 10,
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("ASCII letters"), "{err}");
    let err = LSystem::parse("name S = stamen\nname S = filament\naxiom: S").unwrap_err();
    assert_eq!(
        err,
        LSystemError::Statement("module S is named a second time on line 2".to_owned())
    );
    // A number after `=` makes a constant called "name x", as before.
    let system = LSystem::parse("name x = 2\naxiom: F(name_x)").unwrap();
    assert_eq!(system.constant("name x"), Some(2.0));
    assert!(system.names.is_empty());
}
