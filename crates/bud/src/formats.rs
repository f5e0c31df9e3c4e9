//! The surfaces as files hold them, with one set of checks: the `--bezier`
//! and `--pde` JSON files of `anthesis bud` ([`BezierFile`], [`PdeFile`])
//! and a project's `[templates.source]` (which names the same fields) both
//! make their surfaces here, so a bad file gets the same message from
//! either.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::{BezierCurve, BezierPatch, MAX_STRETCH_TO_BEND, PdeSweep};

/// What is wrong with a surface as a file gives it; each names the field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FormatError {
    /// A Bézier curve (or a row of a patch) without exactly four control
    /// points.
    #[error("{field} needs 4 points [x, y, z] (Bézier control points, base to tip), found {found}")]
    Points {
        /// The field, as the file names it (`margin0`, `row 2 of control`).
        field: String,
        /// How many points it has.
        found: usize,
    },
    /// A control point with a coordinate that is not a finite number.
    #[error("{field} has a non-finite point")]
    NotFinite {
        /// The field, as the file names it.
        field: String,
    },
    /// A patch without exactly four rows of control points.
    #[error("{field} needs 4 rows of 4 control points (base to tip), found {found} rows")]
    Rows {
        /// The field, as the file names it.
        field: String,
        /// How many rows it has.
        found: usize,
    },
    /// The stiffness ratio of a PDE sweep out of its range.
    #[error("stretch_to_bend (k_s/k_b) must be from 0 to {MAX_STRETCH_TO_BEND}, found {found}")]
    StretchToBend {
        /// The ratio given.
        found: f64,
    },
}

/// A cubic Bézier curve from the four control points `points` (base to
/// tip) of the field named `field`.
pub fn bezier_curve(field: &str, points: &[[f64; 3]]) -> Result<BezierCurve, FormatError> {
    let control: [DVec3; 4] = match points {
        [a, b, c, d] => [a, b, c, d].map(|p| DVec3::from_array(*p)),
        _ => {
            return Err(FormatError::Points {
                field: field.to_string(),
                found: points.len(),
            });
        }
    };
    if !control.iter().all(|p| p.is_finite()) {
        return Err(FormatError::NotFinite {
            field: field.to_string(),
        });
    }
    Ok(BezierCurve::new(control))
}

/// A bicubic Bézier patch from the rows of its control net (base to tip,
/// four points across each) in the field named `field`.
pub fn bezier_patch(field: &str, rows: &[Vec<[f64; 3]>]) -> Result<BezierPatch, FormatError> {
    let [a, b, c, d] = rows else {
        return Err(FormatError::Rows {
            field: field.to_string(),
            found: rows.len(),
        });
    };
    let mut control = [[DVec3::ZERO; 4]; 4];
    for (j, row) in [a, b, c, d].into_iter().enumerate() {
        control[j] = bezier_curve(&format!("row {} of {field}", j + 1), row)?.control;
    }
    Ok(BezierPatch::new(control))
}

/// A PDE sweep from its margins and across-tangents (four Bézier control
/// points each, base to tip) and `stretch_to_bend`, `k_s/k_b`.
pub fn pde_sweep(
    [margin0, margin1, tangent0, tangent1]: [&[[f64; 3]]; 4],
    stretch_to_bend: f64,
) -> Result<PdeSweep, FormatError> {
    let (c0, c1) = (
        bezier_curve("margin0", margin0)?,
        bezier_curve("margin1", margin1)?,
    );
    let (t0, t1) = (
        bezier_curve("tangent0", tangent0)?,
        bezier_curve("tangent1", tangent1)?,
    );
    if !(stretch_to_bend.is_finite() && (0.0..=MAX_STRETCH_TO_BEND).contains(&stretch_to_bend)) {
        return Err(FormatError::StretchToBend {
            found: stretch_to_bend,
        });
    }
    Ok(PdeSweep::new(c0, c1, t0, t1, stretch_to_bend))
}

/// The `--bezier` file of `anthesis bud`: the patch's control net, rows
/// from the base to the tip, four `[x, y, z]` points across each.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BezierFile {
    /// The rows of control points, in the template frame.
    pub control: Vec<Vec<[f64; 3]>>,
}

impl BezierFile {
    /// The patch the file holds, checked.
    pub fn patch(&self) -> Result<BezierPatch, FormatError> {
        bezier_patch("control", &self.control)
    }
}

impl From<&BezierPatch> for BezierFile {
    fn from(patch: &BezierPatch) -> Self {
        BezierFile {
            control: patch
                .control
                .iter()
                .map(|row| row.iter().map(|p| p.to_array()).collect())
                .collect(),
        }
    }
}

/// The `--pde` file of `anthesis bud`: a PDE sweep's margins and
/// across-tangents, four `[x, y, z]` Bézier control points each (base to
/// tip), and `k_s/k_b` (0, the cubic, when left out).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PdeFile {
    /// The first margin's control points.
    pub margin0: Vec<[f64; 3]>,
    /// The second margin's control points.
    pub margin1: Vec<[f64; 3]>,
    /// The across-tangent at the first margin.
    pub tangent0: Vec<[f64; 3]>,
    /// The across-tangent at the second margin.
    pub tangent1: Vec<[f64; 3]>,
    /// Stretching against bending stiffness, `k_s/k_b`.
    #[serde(default)]
    pub stretch_to_bend: f64,
}

impl PdeFile {
    /// The sweep the file holds, checked.
    pub fn sweep(&self) -> Result<PdeSweep, FormatError> {
        pde_sweep(
            [&self.margin0, &self.margin1, &self.tangent0, &self.tangent1],
            self.stretch_to_bend,
        )
    }
}

impl From<&PdeSweep> for PdeFile {
    fn from(sweep: &PdeSweep) -> Self {
        let points = |curve: &BezierCurve| curve.control.iter().map(|p| p.to_array()).collect();
        PdeFile {
            margin0: points(&sweep.curve0),
            margin1: points(&sweep.curve1),
            tangent0: points(&sweep.tangent0),
            tangent1: points(&sweep.tangent1),
            stretch_to_bend: sweep.stretch_to_bend(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn files_hold_their_surfaces_exactly() {
        let sweep = crate::lily_petal_surface();
        assert_eq!(PdeFile::from(&sweep).sweep(), Ok(sweep));
        let patch = crate::eustoma_petal_surface();
        assert_eq!(BezierFile::from(&patch).patch(), Ok(patch));
    }

    #[test]
    fn each_check_names_its_field() {
        let row = vec![[1.0, 0.0, 0.0], [0.0; 3], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let three = BezierFile {
            control: vec![row.clone(); 3],
        };
        assert_eq!(
            three.patch().map_err(|e| e.to_string()),
            Err("control needs 4 rows of 4 control points (base to tip), found 3 rows".into())
        );
        let mut short = BezierFile {
            control: vec![row.clone(); 4],
        };
        short.control[1] = vec![[0.0; 3]];
        assert!(
            matches!(short.patch(), Err(FormatError::Points { field, found: 1 })
            if field == "row 2 of control")
        );
        let mut file = PdeFile::from(&crate::lily_petal_surface());
        file.tangent0[2][1] = f64::NAN;
        assert_eq!(
            file.sweep(),
            Err(FormatError::NotFinite {
                field: "tangent0".into()
            })
        );
        let mut file = PdeFile::from(&crate::lily_petal_surface());
        file.stretch_to_bend = MAX_STRETCH_TO_BEND * 2.0;
        assert!(matches!(
            file.sweep(),
            Err(FormatError::StretchToBend { .. })
        ));
    }
}
