use anthesis_garden::buds::RingOrgan;
use glam::DVec2;
fn main() {
    let petal = RingOrgan {
        midrib: [
            DVec2::new(2.0, 0.0),
            DVec2::new(11.0, 8.0),
            DVec2::new(10.0, 34.0),
            DVec2::new(0.9, 44.0),
        ],
        half_width: [1.0, 9.5, 9.0, 0.0],
        offset: 0.0,
        contortion: 0.0,
        top_rounding: 0.0,
    };
    for (name, organ, edge) in [
        ("petal", petal, 1.3),
        (
            "sepal",
            RingOrgan {
                offset: 1.2,
                half_width: [0.8, 8.0, 8.5, 0.0],
                ..petal
            },
            1.4,
        ),
    ] {
        match anthesis_bud::build_organ(&organ, &anthesis_bud::RemeshOptions::new(edge)) {
            Ok(b) => println!("{name}: {:?}", b.quality),
            Err(e) => println!("{name}: {e}"),
        }
    }
}
