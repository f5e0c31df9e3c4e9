//! The lily, bloom and decay (issue 15 item 3): its first 100 keyframes are
//! the lily's opening, and in the 60 after them the tepals shrink, hang
//! lower and curl their tips further down and in (Chaudhry et al.
//! §VI.B), measured with `anthesis_garden::shape`.

use anthesis_flower::Project;
use anthesis_garden::decay::{DECAY_KEYFRAMES, DECAY_START, lily_decay};
use anthesis_garden::flowers;
use anthesis_garden::shape::{OrganShape, organ_shape};
use anthesis_sim::{Selection, run};

/// The shapes of every organ at each keyframe of `frames`.
fn shapes(project: &Project, frames: &[u32]) -> Vec<Vec<OrganShape>> {
    let mut found = Vec::new();
    run(project, &Selection::All, &mut |_, keyframe| {
        if frames.contains(&keyframe.index) {
            found.push(
                keyframe
                    .positions_in_world
                    .iter()
                    .enumerate()
                    .map(|(i, positions)| {
                        organ_shape(&project.flower.template_of(i).mesh, positions)
                            .expect("measurable")
                    })
                    .collect(),
            );
        }
    })
    .unwrap_or_else(|error| panic!("{}: {error}", project.name));
    assert_eq!(found.len(), frames.len());
    found
}

#[test]
fn the_lily_blooms_as_the_lily_does_then_its_tepals_shrink_droop_and_curl() {
    let decay = lily_decay().expect("lily-decay");
    assert_eq!(decay.settings.keyframes, DECAY_KEYFRAMES);
    let lily = flowers::lily().expect("lily");
    let bloom = &shapes(&lily, &[DECAY_START])[0];
    let seen = shapes(&decay, &[DECAY_START, DECAY_KEYFRAMES]);
    let (open, wilted) = (&seen[0], &seen[1]);
    for (i, (mine, lilys)) in open.iter().zip(bloom).enumerate() {
        // The same opening: the keys it adds hold the lily's late maps
        // until step 100 (blended with themselves, so equal but for
        // rounding).
        let tip = |s: &OrganShape| glam::DVec2::new(s.radius_profile[3], s.height_profile[3]);
        assert!(
            tip(mine).distance(tip(lilys)) < 0.01 * lilys.midrib_length,
            "organ {i}: tip {} against the lily's {}",
            tip(mine),
            tip(lilys)
        );
    }
    for (i, (open, wilted)) in open.iter().zip(wilted).enumerate() {
        let shrink = wilted.midrib_length / open.midrib_length;
        assert!(
            (0.8..0.95).contains(&shrink),
            "organ {i}: midrib {:.1} -> {:.1}",
            open.midrib_length,
            wilted.midrib_length
        );
        // The tip hangs lower and the midrib curls on past the open reflex.
        assert!(
            wilted.height_profile[3] < open.height_profile[3] - 5.0,
            "organ {i}: tip height {:.1} -> {:.1}",
            open.height_profile[3],
            wilted.height_profile[3]
        );
        assert!(
            wilted.midrib_turning_deg > open.midrib_turning_deg + 60.0,
            "organ {i}: midrib turning {:.0}° -> {:.0}°",
            open.midrib_turning_deg,
            wilted.midrib_turning_deg
        );
    }
}
