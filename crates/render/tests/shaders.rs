//! Every WGSL file in /shaders parses and validates with naga (no GPU).

use std::path::PathBuf;

fn shaders_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shaders")
}

#[test]
fn every_wgsl_file_parses_and_validates() {
    let mut checked = Vec::new();
    let entries = std::fs::read_dir(shaders_dir()).expect("shaders folder is readable");
    for entry in entries {
        let path = entry.expect("directory entry").path();
        if path.extension().and_then(|e| e.to_str()) != Some("wgsl") {
            continue;
        }
        let mut source = std::fs::read_to_string(&path).expect("shader is UTF-8 text");
        if path.file_name().and_then(|n| n.to_str()) == Some("organ.wgsl") {
            // Compiled with the overlay ramp's stops written in front.
            assert_eq!(source, anthesis_render::SHADER_SOURCE);
            source = anthesis_render::organ_shader_source();
        }
        let module = naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| {
            panic!(
                "{} does not parse:\n{}",
                path.display(),
                e.emit_to_string(&source)
            )
        });
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::empty(),
        )
        .validate(&module)
        .unwrap_or_else(|e| {
            panic!(
                "{} does not validate:\n{}",
                path.display(),
                e.emit_to_string(&source)
            )
        });
        checked.push(path);
    }
    for shader in ["organ.wgsl", "viewport_blit.wgsl"] {
        assert!(
            checked.iter().any(|p| p.ends_with(shader)),
            "{shader} was not among the checked shaders: {checked:?}"
        );
    }
}
