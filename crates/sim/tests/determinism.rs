//! Determinism: the same project gives bit-identical keyframes across runs
//! and whatever the number of threads.

mod common;

use anthesis_flower::Project;
use anthesis_sim::Selection;
use anthesis_sim::fixtures::whorl;
use common::fingerprint;

fn run_on(threads: usize, project: &Project) -> Vec<u64> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool");
    let (keyframes, error) = pool.install(|| common::run_all(project, &Selection::All));
    assert_eq!(error, None, "the run on {threads} threads failed");
    assert_eq!(keyframes.len(), project.settings.keyframes as usize + 1);
    fingerprint(&keyframes)
}

fn assert_same_everywhere(project: &Project) {
    let reference = run_on(1, project);
    assert_eq!(
        run_on(1, project),
        reference,
        "two runs on one thread differ"
    );
    for threads in [2, 4] {
        let other = run_on(threads, project);
        assert_eq!(other.len(), reference.len());
        if let Some(i) = (0..reference.len()).find(|&i| other[i] != reference[i]) {
            panic!(
                "{threads} threads: value {i} differs ({:e} against {:e} on one thread)",
                f64::from_bits(other[i]),
                f64::from_bits(reference[i])
            );
        }
    }
}

#[test]
fn a_whorl_with_collisions_is_bit_identical_across_runs_and_thread_counts() {
    let project = whorl(4, 8, 14, 15);
    assert!(!project.flower.overlaps.is_empty());
    assert_same_everywhere(&project);
}

#[test]
fn organs_pressing_on_each_other_are_bit_identical_across_thread_counts() {
    // Contacts active in most keyframes, so the push-back and the contact
    // penalties are part of what must not depend on scheduling.
    assert_same_everywhere(&common::inner_driven_into_outer(20, true));
}

#[test]
fn the_fingerprint_sees_a_one_bit_change() {
    // The comparison above is only as good as the fingerprint.
    let project = whorl(1, 6, 10, 2);
    let (mut keyframes, error) = common::run_all(&project, &Selection::All);
    assert_eq!(error, None);
    let before = fingerprint(&keyframes);
    let p = &mut keyframes[2].positions_in_world[0][7];
    p.y = f64::from_bits(p.y.to_bits() ^ 1);
    assert_ne!(fingerprint(&keyframes), before);
}
