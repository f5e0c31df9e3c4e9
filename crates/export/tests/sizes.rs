//! File sizes of a lily-sized export (6 organs x 390 vertices x 100
//! keyframes) in every mode, each checked by the validator.
//!
//! `cargo test -p anthesis-export --test sizes -- --nocapture` prints the
//! table; `anthesis_export::glb_size_report` gives it for any flower.

mod common;

use anthesis_export::{Encoding, GlbOptions, glb_bytes, glb_size_report};
use common::*;

#[test]
fn lily_sized_export_sizes_in_every_mode() {
    let tracks = lily_sized_fixture();
    let report = glb_size_report(&tracks, &GlbOptions::default()).expect("report");
    println!("{report}");
    assert_eq!(report.tracks, 7);
    assert_eq!(report.vertices, 6 * 390 + 36);
    assert_eq!(report.keyframes, 100);
    assert_eq!(report.morph_targets, 99);
    assert_eq!(report.sizes.len(), 2 * Encoding::ALL.len());

    let bytes = |e, n| report.bytes(e, n).expect("size");
    // Dense with normals: 6 x 390 x 99 targets x (12 + 12) bytes dominate;
    // the JSON (about 1200 accessors) adds a few percent.
    let dense = bytes(Encoding::Dense, true);
    let target_data = 6 * 390 * 99 * 24;
    assert!(
        dense > target_data && dense < target_data * 107 / 100,
        "{dense}"
    );
    for encoding in Encoding::ALL {
        assert!(bytes(encoding, false) < bytes(encoding, true), "{encoding}");
    }
    // Quantized targets take 8 + 4 bytes per vertex instead of 24.
    assert!(bytes(Encoding::Quantized, true) * 10 < dense * 6);
    // meshopt compresses the quantized streams further.
    assert!(bytes(Encoding::Meshopt, true) < bytes(Encoding::Quantized, true));
    // Every tepal vertex moves, so sparse storage cannot win here; it must
    // never be larger than dense by more than the weights it saves.
    assert!(bytes(Encoding::Sparse, true) <= dense);
}

#[test]
fn lily_sized_exports_pass_the_validator() {
    let tracks = lily_sized_fixture();
    for encoding in Encoding::ALL {
        let options = GlbOptions {
            encoding,
            ..GlbOptions::default()
        };
        let bytes = glb_bytes(&tracks, &options, &mut |_| {}).expect("export");
        assert_valid_glb(&bytes, &format!("lily-{encoding}"));
    }
}
