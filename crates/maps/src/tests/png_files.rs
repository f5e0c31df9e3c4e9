use glam::DVec2;
use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder};

use crate::{BitDepth, DirectionMap, MapError, ScalarMap};

/// A PNG written straight with the `image` crate, as a paint program would.
fn png_with(width: u32, height: u32, colour: ExtendedColorType, raw: &[u8]) -> Vec<u8> {
    let mut png = Vec::new();
    PngEncoder::new(&mut png)
        .write_image(raw, width, height, colour)
        .expect("encodable test image");
    png
}

fn decoded_with_image_crate(png: &[u8]) -> image::DynamicImage {
    image::load_from_memory_with_format(png, image::ImageFormat::Png).expect("valid PNG")
}

/// Deterministic values spread over [0, 1].
fn pseudo_random_unit_values(count: usize) -> Vec<f32> {
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    (0..count)
        .map(|_| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 40) as f32 / (1_u64 << 24) as f32
        })
        .collect()
}

#[test]
fn eight_bit_round_trip_keeps_every_level_exactly() {
    let values: Vec<f32> = (0..256).map(|code| code as f32 / 255.0).collect();
    let map = ScalarMap::new(16, 16, values).expect("256 values");
    let png = map.to_png_bytes(BitDepth::Eight).expect("encodes");
    let image = decoded_with_image_crate(&png);
    assert_eq!(image.color(), image::ColorType::L8);
    assert_eq!(image.as_bytes(), (0..=255).collect::<Vec<u8>>());
    assert_eq!(ScalarMap::from_png_bytes(&png), Ok(map));
}

#[test]
fn sixteen_bit_round_trip_is_exact_to_one_part_in_65535() {
    let values = pseudo_random_unit_values(37 * 23);
    let map = ScalarMap::new(37, 23, values).expect("37x23 values");
    let png = map.to_png_bytes(BitDepth::Sixteen).expect("encodes");
    assert_eq!(
        decoded_with_image_crate(&png).color(),
        image::ColorType::L16
    );
    let loaded = ScalarMap::from_png_bytes(&png).expect("decodes");
    assert_eq!(loaded.size(), (37, 23));
    // Rounding to the nearest code moves a value by at most half a code.
    let tolerance = 0.5 / 65535.0 + 1e-7;
    let worst = map
        .values()
        .iter()
        .zip(loaded.values())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0_f32, f32::max);
    assert!(worst <= tolerance, "worst error {worst}");
    // Values on the 16-bit grid come back exactly, extremes included.
    let on_grid =
        ScalarMap::new(4, 1, vec![0.0, 1.0 / 65535.0, 32768.0 / 65535.0, 1.0]).expect("4 values");
    let png = on_grid.to_png_bytes(BitDepth::Sixteen).expect("encodes");
    assert_eq!(ScalarMap::from_png_bytes(&png), Ok(on_grid));
}

#[test]
fn png_rows_run_from_the_top_of_the_map() {
    // 1 at the top (v = 1), 0 at the bottom.
    let map = ScalarMap::from_fn(3, 4, |point_in_uv| point_in_uv.y.round() as f32);
    let png = map.to_png_bytes(BitDepth::Eight).expect("encodes");
    let image = decoded_with_image_crate(&png).into_luma8();
    assert_eq!(image.get_pixel(1, 0).0, [255]);
    assert_eq!(image.get_pixel(1, 3).0, [0]);
}

#[test]
fn saving_clamps_values_to_the_unit_interval() {
    let map = ScalarMap::new(2, 1, vec![-0.5, 1.5]).expect("2 values");
    let png = map.to_png_bytes(BitDepth::Eight).expect("encodes");
    let loaded = ScalarMap::from_png_bytes(&png).expect("decodes");
    assert_eq!(loaded.values(), &[0.0, 1.0]);
}

#[test]
fn grey_with_alpha_is_read_with_the_alpha_ignored() {
    let png = png_with(2, 1, ExtendedColorType::La8, &[51, 0, 204, 255]);
    let map = ScalarMap::from_png_bytes(&png).expect("grey+alpha is accepted");
    assert_eq!(map.values(), &[0.2, 0.8]);
}

#[test]
fn neutral_grey_rgb_is_accepted_but_a_coloured_pixel_is_refused() {
    let grey_rgb = png_with(2, 1, ExtendedColorType::Rgb8, &[51, 51, 51, 255, 255, 255]);
    let map = ScalarMap::from_png_bytes(&grey_rgb).expect("grey stored as RGB");
    assert_eq!(map.values(), &[0.2, 1.0]);

    // 2x2 RGBA, the bottom-right pixel red.
    let raw = [
        9, 9, 9, 255, 9, 9, 9, 255, //
        9, 9, 9, 255, 255, 0, 0, 255,
    ];
    let coloured = png_with(2, 2, ExtendedColorType::Rgba8, &raw);
    let error = ScalarMap::from_png_bytes(&coloured).expect_err("colour is refused");
    assert_eq!(
        error,
        MapError::NotGrey {
            format: "RGBA 8-bit".to_owned(),
            x: 1,
            y: 1,
            rgb: [255, 0, 0]
        }
    );
    let message = error.to_string();
    assert!(message.contains("greyscale"), "{message}");
    assert!(message.contains("RGBA 8-bit"), "{message}");
}

#[test]
fn bytes_that_are_not_png_are_named() {
    let jpeg = [
        0xff, 0xd8, 0xff, 0xe0, 0x00, 0x10, b'J', b'F', b'I', b'F', 0,
    ];
    assert_eq!(
        ScalarMap::from_png_bytes(&jpeg),
        Err(MapError::NotPng {
            found: "a JPEG image"
        })
    );
    assert_eq!(
        DirectionMap::from_png_bytes(b"e_growth = 0.5\n"),
        Err(MapError::NotPng { found: "text" })
    );
    assert_eq!(
        ScalarMap::from_png_bytes(&[]),
        Err(MapError::NotPng { found: "empty" })
    );
    let message = ScalarMap::from_png_bytes(&jpeg)
        .expect_err("not PNG")
        .to_string();
    assert!(
        message.contains("JPEG") && message.contains("PNG"),
        "{message}"
    );
}

#[test]
fn truncated_and_corrupt_pngs_are_decode_errors() {
    let map = ScalarMap::from_fn(8, 8, |point_in_uv| point_in_uv.x as f32);
    let png = map.to_png_bytes(BitDepth::Eight).expect("encodes");

    let data_start = png
        .windows(4)
        .position(|window| window == b"IDAT")
        .expect("an IDAT chunk")
        + 4;
    let data_length = u32::from_be_bytes(
        png[data_start - 8..data_start - 4]
            .try_into()
            .expect("4 bytes"),
    ) as usize;
    assert!(data_length > 8, "IDAT holds {data_length} bytes");

    // Cut inside the signature, the header, and the image data. (A file cut
    // after its image data, in the end marker, still holds the whole image
    // and is read.)
    for length in [4, 20, 40, data_start + 2, data_start + data_length / 2] {
        let result = ScalarMap::from_png_bytes(&png[..length]);
        assert!(
            matches!(result, Err(MapError::Decode { .. })),
            "cut at {length}: {result:?}"
        );
    }

    // Flip a byte inside the image data: its checksum no longer matches.
    let mut corrupt = png.clone();
    corrupt[data_start + 2] ^= 0x55;
    let result = ScalarMap::from_png_bytes(&corrupt);
    assert!(matches!(result, Err(MapError::Decode { .. })), "{result:?}");

    // A broken header (the width changed without its checksum).
    let mut bad_header = png.clone();
    bad_header[18] = 0x7f;
    let result = ScalarMap::from_png_bytes(&bad_header);
    assert!(matches!(result, Err(MapError::Decode { .. })), "{result:?}");
}

#[test]
fn direction_round_trip_keeps_zero_exact_with_mid_grey() {
    let values = vec![[0.0, 1.0], [-1.0, 0.0], [1.0, -1.0], [0.504, -0.252]];
    let map = DirectionMap::new(2, 2, values).expect("4 values");
    let png = map.to_png_bytes(BitDepth::Eight).expect("encodes");
    let image = decoded_with_image_crate(&png).into_rgb8();
    // u = 0, v = 1, blue = zero.
    assert_eq!(image.get_pixel(0, 0).0, [128, 255, 128]);
    assert_eq!(image.get_pixel(1, 0).0, [1, 128, 128]);
    let loaded = DirectionMap::from_png_bytes(&png).expect("decodes");
    assert_eq!(loaded.values()[0], [0.0, 1.0]);
    assert_eq!(loaded.values()[1], [-1.0, 0.0]);
    assert_eq!(loaded.values()[2], [1.0, -1.0]);
    // Off-grid values move to the nearest of the 127 steps per unit.
    for (a, b) in loaded.values()[3].iter().zip(map.values()[3]) {
        assert!((a - b).abs() <= 0.5 / 127.0, "{a} vs {b}");
    }
    assert_eq!(loaded.values()[3], [64.0 / 127.0, -32.0 / 127.0]);

    // A flat 50 % grey painting means no direction.
    let grey = png_with(1, 1, ExtendedColorType::Rgb8, &[128, 128, 128]);
    let zero = DirectionMap::from_png_bytes(&grey).expect("RGB");
    assert_eq!(zero.sample(DVec2::splat(0.5)), DVec2::ZERO);
}

#[test]
fn direction_sixteen_bit_round_trip_and_rgba_input() {
    let map = DirectionMap::from_fn(5, 3, |point_in_uv| {
        DVec2::new(point_in_uv.x * 2.0 - 1.0, 0.3 - point_in_uv.y)
    });
    let png = map.to_png_bytes(BitDepth::Sixteen).expect("encodes");
    assert_eq!(
        decoded_with_image_crate(&png).color(),
        image::ColorType::Rgb16
    );
    let loaded = DirectionMap::from_png_bytes(&png).expect("decodes");
    let tolerance = 0.5 / 32767.0 + 1e-7;
    for (a, b) in map.values().iter().zip(loaded.values()) {
        assert!((a[0] - b[0]).abs() <= tolerance && (a[1] - b[1]).abs() <= tolerance);
    }

    // RGBA: blue and alpha ignored; code 0 reads as -1.
    let rgba = png_with(1, 1, ExtendedColorType::Rgba8, &[0, 255, 17, 3]);
    let map = DirectionMap::from_png_bytes(&rgba).expect("RGBA");
    assert_eq!(map.values(), &[[-1.0, 1.0]]);
}

#[test]
fn grey_png_for_a_direction_map_is_an_unsupported_format() {
    let grey = ScalarMap::constant(0.5)
        .to_png_bytes(BitDepth::Sixteen)
        .expect("encodes");
    let error = DirectionMap::from_png_bytes(&grey).expect_err("needs colour");
    assert!(
        matches!(&error, MapError::UnsupportedFormat { found, .. } if found == "grey 16-bit"),
        "{error:?}"
    );
    assert!(error.to_string().contains("RGB"), "{error}");
}

#[test]
fn files_round_trip_and_errors_name_the_file() {
    let folder = tempfile::tempdir().expect("temporary folder");
    let map = ScalarMap::from_fn(6, 5, |point_in_uv| (point_in_uv.x * point_in_uv.y) as f32);
    let path = folder.path().join("e_growth.png");
    map.save_png(&path, BitDepth::Sixteen).expect("saves");
    let loaded = ScalarMap::load_png(&path).expect("loads");
    assert_eq!(loaded.size(), (6, 5));

    let direction = DirectionMap::constant(DVec2::new(0.0, 1.0));
    let direction_path = folder.path().join("direction.png");
    direction
        .save_png(&direction_path, BitDepth::Eight)
        .expect("saves");
    assert_eq!(DirectionMap::load_png(&direction_path), Ok(direction));

    let missing = folder.path().join("missing.png");
    let error = ScalarMap::load_png(&missing).expect_err("no such file");
    assert!(matches!(&error, MapError::Io { path, .. } if path == &missing));
    assert!(error.to_string().contains("missing.png"), "{error}");

    let text_path = folder.path().join("bend.png");
    std::fs::write(&text_path, "not an image").expect("writes");
    let error = ScalarMap::load_png(&text_path).expect_err("text");
    assert_eq!(error.root(), &MapError::NotPng { found: "text" });
    assert!(matches!(&error, MapError::InFile { path, .. } if path == &text_path));
    let message = error.to_string();
    assert!(
        message.contains("bend.png") && message.contains("not a PNG"),
        "{message}"
    );

    // The loader can attach a file to a size error itself.
    let error = loaded
        .check_size((8, 8))
        .map_err(|error| error.in_file(&path))
        .expect_err("6x5 is not 8x8");
    assert!(error.to_string().contains("e_growth.png"), "{error}");
    assert!(matches!(error.root(), MapError::WrongSize { .. }));
}

#[test]
fn writing_into_a_missing_folder_is_an_io_error() {
    let folder = tempfile::tempdir().expect("temporary folder");
    let path = folder.path().join("no-such-folder").join("stretch.png");
    let result = ScalarMap::constant(1.0).save_png(&path, BitDepth::Eight);
    assert!(
        matches!(&result, Err(MapError::Io { path: p, .. }) if p == &path),
        "{result:?}"
    );
}

#[test]
fn maps_wider_or_taller_than_the_limit_are_refused_before_decoding() {
    let side = crate::MAX_MAP_SIDE;
    let at_limit = png_with(side, 1, ExtendedColorType::L8, &vec![128; side as usize]);
    assert_eq!(
        ScalarMap::from_png_bytes(&at_limit)
            .expect("at the limit")
            .size(),
        (side, 1)
    );
    for (width, height) in [(side + 1, 1), (1, side + 1)] {
        let count = (width * height) as usize;
        let png = png_with(width, height, ExtendedColorType::L8, &vec![128; count]);
        let error = ScalarMap::from_png_bytes(&png).expect_err("too large");
        assert_eq!(error, MapError::TooManyPixels { width, height });
        let error = DirectionMap::from_png_bytes(&png).expect_err("too large");
        assert_eq!(error, MapError::TooManyPixels { width, height });
    }
    assert!(
        MapError::TooManyPixels {
            width: 16384,
            height: 16384
        }
        .to_string()
        .starts_with("the map is 16384x16384 pixels, more than the limit of 4096x4096;")
    );
}

#[test]
fn only_regular_files_within_the_size_limit_are_read() {
    let folder = tempfile::tempdir().expect("temporary folder");
    let fifo = folder.path().join("pipe.png");
    let status = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo runs");
    assert!(status.success());
    // A sparse file: larger than the limit without using the disk.
    let huge = folder.path().join("huge.png");
    std::fs::File::create(&huge)
        .and_then(|file| file.set_len(crate::MAX_PNG_BYTES + 1))
        .expect("sparse file");
    let cases: [(&std::path::Path, &str); 4] = [
        (
            std::path::Path::new("/dev/zero"),
            "it is a character device (like /dev/zero), not a regular file",
        ),
        (
            std::path::Path::new("/dev/urandom"),
            "it is a character device (like /dev/zero), not a regular file",
        ),
        (&fifo, "it is a named pipe (FIFO), not a regular file"),
        (
            &huge,
            "it is 256 MiB (268435457 bytes), more than the limit of 256 MiB for a PNG map",
        ),
    ];
    for (path, expected) in cases {
        for error in [
            ScalarMap::load_png(path).expect_err("refused"),
            DirectionMap::load_png(path).expect_err("refused"),
        ] {
            match &error {
                MapError::Io { path: p, message } => {
                    assert_eq!(p, path);
                    assert!(message.starts_with(expected), "{path:?}: {message}");
                }
                other => panic!("{path:?}: expected an Io error, got {other:?}"),
            }
        }
    }
}
