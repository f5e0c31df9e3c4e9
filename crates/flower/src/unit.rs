//! What one length of a project is in the real world: a project's `unit`
//! (`unit = "1.8 mm"` in the file, next to its name), so exports can write
//! the flower at its real size (glTF in metres, USD with `metersPerUnit`, OBJ
//! in the project's unit with a comment) and `anthesis info` can say how
//! large it is. The simulation never reads it: lengths stay in project
//! units, and a unit only scales what leaves the program.

use std::fmt;

/// A real length: a positive amount of one of the units people measure
/// flowers in, kept as written (`1.8 mm` stays `1.8 mm`, not `0.0018 m`).
/// The amount is a decimal, `digits` / 10^`decimals` (trailing zeros
/// dropped), so it is exact and a `Flower` grows by only 8 bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Unit {
    digits: u32,
    decimals: u8,
    symbol: Symbol,
}

/// The most decimals an amount may have.
const MAX_DECIMALS: usize = 9;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Symbol {
    Micrometre,
    Millimetre,
    Centimetre,
    Metre,
}

impl Symbol {
    const ALL: [Symbol; 4] = [
        Symbol::Micrometre,
        Symbol::Millimetre,
        Symbol::Centimetre,
        Symbol::Metre,
    ];

    /// How many of it make a metre (a division by it rounds correctly:
    /// 1.8 mm is 0.0018 m, not 0.0018000000000000002).
    fn per_metre(self) -> f64 {
        match self {
            Symbol::Micrometre => 1e6,
            Symbol::Millimetre => 1e3,
            Symbol::Centimetre => 1e2,
            Symbol::Metre => 1.0,
        }
    }

    fn text(self) -> &'static str {
        match self {
            Symbol::Micrometre => "µm",
            Symbol::Millimetre => "mm",
            Symbol::Centimetre => "cm",
            Symbol::Metre => "m",
        }
    }

    fn parse(text: &str) -> Option<Symbol> {
        match text {
            "um" | "µm" | "μm" => Some(Symbol::Micrometre),
            _ => Symbol::ALL.into_iter().find(|s| s.text() == text),
        }
    }
}

/// Why a unit's text is not a unit.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "`{text}` is not a length: write a positive number and µm, mm, cm or m, \
     such as \"1.8 mm\" (or just \"mm\" for one millimetre)"
)]
pub struct UnitError {
    /// The text as given.
    pub text: String,
}

impl Unit {
    /// One metre: what a unit meant to every export before projects stated
    /// their unit, and what a project that states none still means.
    pub const METRE: Unit = Unit {
        digits: 1,
        decimals: 0,
        symbol: Symbol::Metre,
    };

    /// One millimetre.
    pub const MILLIMETRE: Unit = Unit {
        digits: 1,
        decimals: 0,
        symbol: Symbol::Millimetre,
    };

    /// `amount` millimetres (as its shortest decimal, `1.8`); `None` unless
    /// it is a positive number of at most nine decimals.
    pub fn millimetres(amount: f64) -> Option<Unit> {
        Unit::parse(&format!("{amount} mm")).ok()
    }

    /// Reads `"1.8 mm"`, `"1.8mm"` or `"mm"` (one of it): a positive,
    /// finite number and `µm` (or `um`), `mm`, `cm` or `m`.
    pub fn parse(text: &str) -> Result<Unit, UnitError> {
        let error = || UnitError {
            text: text.to_string(),
        };
        let trimmed = text.trim();
        let split = trimmed
            .find(|c: char| c.is_alphabetic() || c == 'µ' || c == 'μ')
            .ok_or_else(error)?;
        let (number, symbol) = trimmed.split_at(split);
        let symbol = Symbol::parse(symbol.trim()).ok_or_else(error)?;
        let number = number.trim();
        let (whole, fraction) = match number.split_once('.') {
            _ if number.is_empty() => ("1", ""),
            Some((whole, fraction)) => (whole, fraction.trim_end_matches('0')),
            None => (number, ""),
        };
        let all_digits = |s: &str| s.chars().all(|c| c.is_ascii_digit());
        if !(all_digits(whole) && all_digits(fraction))
            || (whole.is_empty() && fraction.is_empty())
            || fraction.len() > MAX_DECIMALS
        {
            return Err(error());
        }
        let digits: u32 = format!("{whole}{fraction}").parse().map_err(|_| error())?;
        if digits == 0 {
            return Err(error());
        }
        Ok(Unit {
            digits,
            decimals: fraction.len() as u8,
            symbol,
        })
    }

    /// The unit in metres (how glTF and USD want lengths): one division of
    /// exact numbers, so correctly rounded (`1.8 mm` is 0.0018).
    pub fn metres(&self) -> f64 {
        f64::from(self.digits) / (10f64.powi(i32::from(self.decimals)) * self.symbol.per_metre())
    }

    /// `length` project units as a real length people read: in mm below
    /// 10 cm, cm below 1 m, else m, to three significant digits
    /// (`"8.96 cm"`).
    pub fn describe(&self, length: f64) -> String {
        let metres = length * self.metres();
        let (value, symbol) = if metres.abs() < 0.1 {
            (metres * 1e3, "mm")
        } else if metres.abs() < 1.0 {
            (metres * 1e2, "cm")
        } else {
            (metres, "m")
        };
        let digits = if value.abs() >= 100.0 {
            0
        } else if value.abs() >= 10.0 {
            1
        } else {
            2
        };
        format!("{value:.digits$} {symbol}")
    }
}

impl Default for Unit {
    /// [`Unit::METRE`].
    fn default() -> Self {
        Unit::METRE
    }
}

impl fmt::Display for Unit {
    /// As the project file writes it: `1.8 mm`, `1 m`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let scale = 10u32.pow(u32::from(self.decimals));
        let (whole, fraction) = (self.digits / scale, self.digits % scale);
        match self.decimals {
            0 => write!(f, "{whole} {}", self.symbol.text()),
            d => write!(
                f,
                "{whole}.{fraction:0width$} {}",
                self.symbol.text(),
                width = usize::from(d)
            ),
        }
    }
}

impl std::str::FromStr for Unit {
    type Err = UnitError;

    fn from_str(text: &str) -> Result<Unit, UnitError> {
        Unit::parse(text)
    }
}

/// What a project that states no unit is taken to mean, for the places
/// that show real sizes (`anthesis info`):
/// projects made before units existed keep their meaning.
pub fn unstated_note() -> &'static str {
    "the project does not say what its unit is, so one unit is taken as one metre, as \
     before; to export it at its real size, add e.g. `unit = \"1 mm\"` after its \
     `name = …` line in the project file (a number and µm, mm, cm or m)"
}

/// The note a project that states no unit (made before format version 9)
/// is opened with, on the terminal and in the window's log: it keeps its
/// old meaning, one unit one metre, and the note says so and how to state
/// one. None when the project states its unit.
pub fn note_if_unstated(project: &crate::Project) -> Option<String> {
    project
        .flower
        .unit
        .is_none()
        .then(|| format!("note: {}", unstated_note()))
}

/// How large `flower` is, as `anthesis info` prints it: one line for the
/// bud (its organs placed as in keyframe 0 and its parts: height along the
/// axis and width across) and one per template (its mesh's length along
/// the organ, +Y of the template frame), in real lengths when the flower
/// states its unit, else in units with [`unstated_note`].
pub fn size_lines(flower: &crate::Flower) -> Vec<String> {
    let mut min = glam::DVec3::splat(f64::INFINITY);
    let mut max = glam::DVec3::splat(f64::NEG_INFINITY);
    let mut add = |p: glam::DVec3| {
        min = min.min(p);
        max = max.max(p);
    };
    for (i, organ) in flower.organs.iter().enumerate() {
        for &p in &flower.template_of(i).mesh.positions {
            add(organ.placement.world_from_template(p, 0.0));
        }
    }
    for piece in crate::parts::part_pieces(flower) {
        piece.positions_at(0).into_iter().for_each(&mut add);
    }
    let length = |l: f64| match flower.unit {
        Some(unit) => unit.describe(l),
        None => format!("{l:.1} units"),
    };
    let mut lines = Vec::new();
    if min.x <= max.x {
        let size = max - min;
        let unit = match flower.unit {
            Some(unit) => format!("one unit is {unit}"),
            None => unstated_note().to_string(),
        };
        lines.push(format!(
            "size bud {} tall, {} by {} across ({unit})",
            length(size.y),
            length(size.x),
            length(size.z)
        ));
    }
    for template in &flower.templates {
        let ys = template.mesh.positions.iter().map(|p| p.y);
        let (low, high) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
            (a.min(y), b.max(y))
        });
        if low <= high {
            lines.push(format!(
                "size template {} {} long in the bud",
                template.name,
                length(high - low)
            ));
        }
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_read_as_people_write_them_and_write_back_the_same() {
        for (text, metres) in [
            ("1.8 mm", 0.0018),
            ("1.8mm", 0.0018),
            (" mm ", 0.001),
            ("2 cm", 0.02),
            ("1 m", 1.0),
            ("250 um", 0.00025),
            ("250 µm", 0.00025),
        ] {
            let unit = Unit::parse(text).expect(text);
            assert_eq!(unit.metres(), metres, "{text}");
            assert_eq!(Unit::parse(&unit.to_string()), Ok(unit), "{text}");
        }
        assert_eq!(Unit::parse("1.8 mm").expect("mm").to_string(), "1.8 mm");
        assert_eq!(Unit::MILLIMETRE.to_string(), "1 mm");
        assert_eq!(Unit::millimetres(1.8), Unit::parse("1.8 mm").ok());
        assert_eq!(Unit::millimetres(-1.0), None);
        assert_eq!(Unit::parse("1.80 mm"), Unit::parse("1.8 mm"));
        assert_eq!(Unit::parse("0.05 cm").expect("cm").to_string(), "0.05 cm");
        assert_eq!(Unit::parse(".5 cm").expect("cm").metres(), 0.005);
        // A flower keeps its unit in 8 bytes.
        assert_eq!(std::mem::size_of::<Option<Unit>>(), 8);
    }

    #[test]
    fn what_is_not_a_length_is_refused() {
        for text in [
            "", "1.8", "1.8 ft", "-2 mm", "0 mm", "nan mm", "inf m", "mm mm", "1e-400 m",
        ] {
            let error = Unit::parse(text).expect_err(text);
            assert!(error.to_string().contains("is not a length"), "{error}");
        }
    }

    #[test]
    fn lengths_are_described_in_the_unit_people_would_use() {
        let unit = Unit::parse("1.8 mm").expect("mm");
        assert_eq!(unit.describe(50.0), "90.0 mm");
        assert_eq!(unit.describe(77.0), "13.9 cm");
        assert_eq!(unit.describe(1000.0), "1.80 m");
        assert_eq!(Unit::METRE.describe(0.005), "5.00 mm");
    }
}
