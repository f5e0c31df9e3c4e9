//! Every WGSL file in `shaders/` parses and validates with naga (no GPU).

use std::path::Path;

#[test]
fn every_shader_parses_and_validates() {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shaders");
    let mut checked = Vec::new();
    for entry in std::fs::read_dir(&folder).expect("shaders/ exists") {
        let path = entry.expect("readable entry").path();
        if path.extension().is_none_or(|e| e != "wgsl") {
            continue;
        }
        let source = std::fs::read_to_string(&path).expect("readable shader");
        let module = naga::front::wgsl::parse_str(&source)
            .unwrap_or_else(|e| panic!("{}: {}", path.display(), e.emit_to_string(&source)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{}: {e:?}", path.display()));
        checked.push(
            path.file_name()
                .expect("name")
                .to_string_lossy()
                .into_owned(),
        );
    }
    checked.sort();
    assert!(
        checked.contains(&"organ.wgsl".to_string())
            && checked.contains(&"viewport_blit.wgsl".to_string()),
        "checked {checked:?}"
    );
}

#[test]
fn the_app_embeds_the_blit_shader_it_validates() {
    let on_disk = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../shaders/viewport_blit.wgsl"),
    )
    .expect("shader file");
    assert_eq!(anthesis_app::desktop::viewport::BLIT_SHADER_SOURCE, on_disk);
}
