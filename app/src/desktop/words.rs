//! Plain words for the symbols the method uses: the one table every panel
//! takes its parameter names and tooltips from. Each entry keeps the
//! symbol (what the paper, the project file and the log call it, shown in
//! brackets for experts) and says in plain words what the value does to
//! the flower and in what unit it is counted.

/// One parameter's words.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Word {
    /// What the paper, the project file and the log call it.
    pub symbol: &'static str,
    /// Its name in plain words.
    pub plain: &'static str,
    /// What it does to the flower.
    pub does: &'static str,
    /// The unit it is counted in.
    pub unit: &'static str,
}

/// The table: every parameter a panel shows by its symbol.
pub const WORDS: &[Word] = &[
    // The template's parameters.
    Word {
        symbol: "dg",
        plain: "Growth per step",
        does: "The most a triangle grows in one step: it grows by a factor 1 + dg × map value \
               every step. Larger opens faster; negative shrinks (wilting). Paper: 0.003.",
        unit: "fraction of its size per step",
    },
    Word {
        symbol: "thickness",
        plain: "Thickness",
        does: "Distance to the imaginary inner surface. Inner growth larger than base growth \
               bends the petal outwards; a thinner petal bends more for the same difference. \
               Paper: lily 0.2, Eustoma 0.1.",
        unit: "project units (lengths)",
    },
    Word {
        symbol: "Ks",
        plain: "Stretch stiffness",
        does: "How strongly the petal keeps its grown size along its surface (edges keep their \
               rest length); multiplied by the stretch map. Paper: 20 (lily), 10 (Eustoma).",
        unit: "relative stiffness (no unit)",
    },
    Word {
        symbol: "Kb",
        plain: "Bend stiffness",
        does: "How strongly the petal keeps its grown curvature (hinges keep their rest \
               angle); multiplied by the bend map. Paper: 20 (lily), 10 (Eustoma).",
        unit: "relative stiffness (no unit)",
    },
    Word {
        symbol: "keyframes",
        plain: "Steps",
        does: "How many simulation steps follow the bud, one keyframe each, for the whole \
               project. More steps: a longer, finer opening. Paper: 100.",
        unit: "keyframes",
    },
    Word {
        symbol: "v max",
        plain: "Base height",
        does: "Particles from the base up to this v are the organ's base: they hold it on the \
               receptacle (v runs from the base, 0, to the tip, 1).",
        unit: "UV (0 to 1, base to tip)",
    },
    Word {
        symbol: "u min",
        plain: "Base from",
        does: "Where the base region starts across the organ (u runs across it, the midrib at \
               0.5).",
        unit: "UV (0 to 1, across)",
    },
    Word {
        symbol: "u max",
        plain: "Base to",
        does: "Where the base region ends across the organ.",
        unit: "UV (0 to 1, across)",
    },
    Word {
        symbol: "from step",
        plain: "From step",
        does: "The tilt starts after this step.",
        unit: "steps",
    },
    Word {
        symbol: "to step",
        plain: "To step",
        does: "The tilt has added all its degrees at this step.",
        unit: "steps",
    },
    Word {
        symbol: "degrees",
        plain: "Tilt",
        does: "How far the organ tilts at its base over the ramp; positive tilts it outwards.",
        unit: "degrees",
    },
    // The maps (the paint panel).
    Word {
        symbol: "e-growth",
        plain: "Growth along",
        does: "How much the petal's base layer grows along the growth direction: 0 no growth, \
               1 the full dg per step. More makes the petal longer.",
        unit: "fraction of dg (0 to 1)",
    },
    Word {
        symbol: "w-growth",
        plain: "Growth across",
        does: "How much the petal's base layer grows across the growth direction: more makes \
               it wider.",
        unit: "fraction of dg (0 to 1)",
    },
    Word {
        symbol: "e-growth-in",
        plain: "Growth along, inner side",
        does: "Growth of the inner layer along the growth direction: more than the base layer \
               bends the petal outwards along its length (it opens and curls back).",
        unit: "fraction of dg (0 to 1)",
    },
    Word {
        symbol: "w-growth-in",
        plain: "Growth across, inner side",
        does: "Growth of the inner layer across the growth direction: more than the base layer \
               rolls the petal's sides outwards.",
        unit: "fraction of dg (0 to 1)",
    },
    Word {
        symbol: "stretch",
        plain: "Stretch stiffness map",
        does: "Where the petal resists stretching more or less: multiplies Ks.",
        unit: "multiplier (1 = Ks)",
    },
    Word {
        symbol: "bend",
        plain: "Bend stiffness map",
        does: "Where the petal resists bending more or less: multiplies Kb.",
        unit: "multiplier (1 = Kb)",
    },
    Word {
        symbol: "direction",
        plain: "Growth direction",
        does: "Which way 'along' points on the petal: drag to paint the direction the growth \
               maps' 'along' follows.",
        unit: "a direction in UV",
    },
    Word {
        symbol: "colour",
        plain: "Colour mix",
        does: "Where the second colour shows over the base colour (what the flower looks \
               like; not simulated).",
        unit: "0 base colour to 1 second colour",
    },
    // The brush.
    Word {
        symbol: "radius",
        plain: "Brush size",
        does: "The brush radius ([ and ] change it).",
        unit: "UV units (the layout is 1 wide)",
    },
    Word {
        symbol: "strength",
        plain: "Brush strength",
        does: "How much one dab changes a value (Shift+[ and Shift+] change it).",
        unit: "0 to 1",
    },
    Word {
        symbol: "hardness",
        plain: "Brush hardness",
        does: "The fraction of the radius painted at full strength; the rest fades out.",
        unit: "fraction of the radius (0 to 1)",
    },
    Word {
        symbol: "value",
        plain: "Brush value",
        does: "What set moves towards, and what add and subtract add or take away.",
        unit: "the map's values (0 to 1)",
    },
    // The two-state opening.
    Word {
        symbol: "g",
        plain: "Opening speed",
        does: "The growth rate g of G(t; g, T) (eq. 4): 6 reaches the open shape at T, more \
               overshoots it, less stops short.",
        unit: "no unit",
    },
    Word {
        symbol: "T",
        plain: "Opening ends at",
        does: "T of G(t; g, T): the keyframe at which the opening ends (held after).",
        unit: "keyframes",
    },
    // The resolution.
    Word {
        symbol: "mean edge",
        plain: "Mesh detail",
        does: "Every template is simulated remeshed at this mean edge length, with the \
               painted maps unchanged: longer edges are coarse and quick to paint with, \
               shorter ones fine for the final export. Off: the meshes as built. Paper: lily \
               1.3, Eustoma 2.0.",
        unit: "project units (edge length)",
    },
];

/// The words for `symbol` (a symbol missing from the table is its own
/// plain name, with no explanation: the table's test lists every symbol a
/// panel asks for).
pub fn word(symbol: &str) -> Word {
    WORDS
        .iter()
        .find(|w| w.symbol == symbol)
        .copied()
        .unwrap_or(Word {
            symbol: "",
            plain: "",
            does: "",
            unit: "",
        })
}

/// The label of `symbol`'s field: its plain name with the symbol in
/// brackets ("Growth along, inner side (e-growth-in)"), the plain name
/// alone where it is the symbol in other words' case.
pub fn label(symbol: &str) -> String {
    let w = word(symbol);
    if w.plain.is_empty() {
        symbol.to_owned()
    } else if w.plain.eq_ignore_ascii_case(symbol) {
        w.plain.to_owned()
    } else {
        format!("{} ({symbol})", w.plain)
    }
}

/// The tooltip of `symbol`'s field: what it does to the flower, its unit
/// and its symbol.
pub fn tooltip(symbol: &str) -> String {
    let w = word(symbol);
    if w.does.is_empty() {
        return symbol.to_owned();
    }
    format!("{}\nUnit: {}.\nSymbol: {symbol}.", w.does, w.unit)
}

/// The symbols the panels ask the table for (the parameters, base region,
/// joint schedule, maps, brush, two-state opening and resolution).
pub const PANEL_SYMBOLS: &[&str] = &[
    "dg",
    "thickness",
    "Ks",
    "Kb",
    "keyframes",
    "v max",
    "u min",
    "u max",
    "from step",
    "to step",
    "degrees",
    "e-growth",
    "w-growth",
    "e-growth-in",
    "w-growth-in",
    "stretch",
    "bend",
    "direction",
    "colour",
    "radius",
    "strength",
    "hardness",
    "value",
    "g",
    "T",
    "mean edge",
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_symbol_a_panel_shows_has_a_plain_name_a_meaning_and_a_unit_once() {
        for symbol in PANEL_SYMBOLS {
            let entries = WORDS.iter().filter(|w| w.symbol == *symbol).count();
            assert_eq!(entries, 1, "{symbol} is in the table {entries} times");
            let w = word(symbol);
            assert!(!w.plain.is_empty() && !w.does.is_empty() && !w.unit.is_empty());
            let tip = tooltip(symbol);
            assert!(tip.contains(w.unit) && tip.contains(symbol), "{tip}");
        }
        // Every map the paint panel offers is in it.
        for kind in anthesis_maps::MapKind::ALL {
            assert!(PANEL_SYMBOLS.contains(&kind.label()), "{}", kind.label());
        }
        assert_eq!(WORDS.len(), PANEL_SYMBOLS.len(), "no entry nobody asks for");
    }

    #[test]
    fn a_label_keeps_the_symbol_beside_the_plain_name() {
        assert_eq!(
            label("e-growth-in"),
            "Growth along, inner side (e-growth-in)"
        );
        assert_eq!(label("Ks"), "Stretch stiffness (Ks)");
        // Not in the table: the symbol alone, never an empty label.
        assert_eq!(label("no such symbol"), "no such symbol");
        assert_eq!(tooltip("no such symbol"), "no such symbol");
    }
}
