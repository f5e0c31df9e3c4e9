//! Organs on the receptacle: whorls and phyllotactic spirals, and the
//! overlap rules that tell the collision handling which organ lies inside
//! which (paper §5.3, Fig. 12).
//!
//! Each organ is described by where its base sits (distance from the axis,
//! height, azimuth) and by the angle it spans around the axis at its widest
//! ([`Whorl::half_span_deg`]); two organs are given an overlap rule only
//! where those spans meet, so a rule always pairs organs that really touch.

use crate::{Organ, Overlap, Placement};
use glam::DVec3;

/// The golden divergence angle of spiral phyllotaxis, 360° (1 − 1/φ)
/// (the floral blossom paper §3.2).
pub const GOLDEN_ANGLE_DEG: f64 = 137.507_764_050_037_85;

/// A ring of identical organs around the axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Whorl {
    /// Organ names are `<name>-1`, `<name>-2`, … counter-clockwise seen from
    /// above (increasing azimuth).
    pub name: String,
    /// Index of the organs' template in the flower.
    pub template: usize,
    /// How many organs the ring holds, evenly spaced in azimuth.
    pub count: usize,
    /// Azimuth of the first organ; the others follow every 360°/count.
    pub offset_deg: f64,
    /// Distance of the organs' bases from the axis.
    pub radius: f64,
    /// Height of the organs' bases on the receptacle.
    pub height: f64,
    /// Initial joint angle (positive tilts outwards).
    pub joint_angle_deg: f64,
    /// Half the angle about the axis an organ covers at its widest.
    pub half_span_deg: f64,
}

impl Whorl {
    /// Azimuth of organ `k` (0-based).
    pub fn azimuth_deg(&self, k: usize) -> f64 {
        self.offset_deg + 360.0 * k as f64 / self.count.max(1) as f64
    }

    /// The organs of this whorl.
    pub fn organs(&self) -> Vec<Organ> {
        (0..self.count)
            .map(|k| Organ {
                name: format!("{}-{}", self.name, k + 1),
                template: self.template,
                placement: placement(
                    self.azimuth_deg(k),
                    self.radius,
                    self.height,
                    self.joint_angle_deg,
                ),
            })
            .collect()
    }

    /// Whether organs `a` and `b` of this whorl cover overlapping angles.
    fn spans_meet(&self, a: usize, b: usize) -> bool {
        angular_distance_deg(self.azimuth_deg(a), self.azimuth_deg(b)) < 2.0 * self.half_span_deg
    }
}

/// The placement of an organ whose base sits at `radius` from the axis and
/// `height` on it, facing away from the axis at `azimuth_deg`.
pub fn placement(azimuth_deg: f64, radius: f64, height: f64, joint_angle_deg: f64) -> Placement {
    let a = azimuth_deg.to_radians();
    Placement {
        position: DVec3::new(radius * a.sin(), height, radius * a.cos()),
        azimuth_deg,
        joint_angle_deg,
        orientation: glam::DQuat::IDENTITY,
    }
}

/// The smaller angle between two azimuths, in `[0, 180]`.
pub fn angular_distance_deg(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(360.0);
    d.min(360.0 - d)
}

/// Organs placed by whorls, and their overlap rules.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Arrangement {
    /// The organs, placed, in the order their whorls or spiral give them.
    pub organs: Vec<Organ>,
    /// Which organ lies inside which, as indices into `organs`.
    pub overlaps: Vec<Overlap>,
}

/// The most overlap rules a structure may make (a flower's organs meet
/// their few neighbours; a ring of organs each spanning the whole circle
/// would otherwise make a rule for every pair).
pub const MAX_OVERLAP_RULES: usize = 100_000;

/// Nested whorls, innermost first: every organ lies inside each organ of
/// an outer whorl whose span it meets (the lily's petals inside its sepals).
/// Organs of one whorl get no rule between them (they sit side by side).
pub fn nested_whorls(whorls: &[Whorl]) -> Arrangement {
    // No count of rules passes usize::MAX.
    match nested_whorls_within(whorls, usize::MAX) {
        Ok(arrangement) | Err(arrangement) => arrangement,
    }
}

/// [`nested_whorls`], stopping with what it made so far (`Err`) as soon as
/// there are more than `limit` overlap rules. Only the organs of an outer
/// whorl within an organ's span are looked at, so the work grows with the
/// organs and the rules, not with every pair.
pub fn nested_whorls_within(whorls: &[Whorl], limit: usize) -> Result<Arrangement, Arrangement> {
    let mut organs = Vec::new();
    let mut first_index = Vec::new();
    for whorl in whorls {
        first_index.push(organs.len());
        organs.extend(whorl.organs());
    }
    let mut overlaps = Vec::new();
    let mut outers = Vec::new();
    for (i, inner) in whorls.iter().enumerate() {
        for (j, outer) in whorls.iter().enumerate().skip(i + 1) {
            let reach = inner.half_span_deg + outer.half_span_deg;
            for a in 0..inner.count {
                let azimuth = inner.azimuth_deg(a);
                outers.clear();
                for b in ring_window(outer, azimuth, reach) {
                    let distance = angular_distance_deg(azimuth, outer.azimuth_deg(b));
                    if distance < reach {
                        outers.push(b);
                    }
                }
                outers.sort_unstable();
                outers.dedup();
                overlaps.extend(outers.iter().map(|&b| Overlap {
                    inner: first_index[i] + a,
                    outer: first_index[j] + b,
                }));
                if overlaps.len() > limit {
                    return Err(Arrangement { organs, overlaps });
                }
            }
        }
    }
    Ok(Arrangement { organs, overlaps })
}

/// The organs of `ring` whose azimuths may lie within `reach` degrees of
/// `azimuth` (a few more at the window's ends; all when the window is as
/// wide as the ring).
fn ring_window(ring: &Whorl, azimuth: f64, reach: f64) -> Box<dyn Iterator<Item = usize>> {
    let n = ring.count;
    let step = 360.0 / n.max(1) as f64;
    let wide = !(reach.is_finite() && azimuth.is_finite() && ring.offset_deg.is_finite())
        || 2.0 * reach / step + 3.0 >= n as f64;
    if wide {
        return Box::new(0..n);
    }
    let centre = (azimuth - ring.offset_deg) / step;
    let half = reach / step;
    let first = (centre - half).floor() as i64 - 1;
    let last = (centre + half).ceil() as i64 + 1;
    let n = n as i64;
    Box::new((first..=last).map(move |k| k.rem_euclid(n) as usize))
}
/// One contorted whorl (Eustoma's corolla, paper Fig. 12(b)): each organ's
/// right side (towards increasing azimuth) lies beneath its right-hand
/// neighbour. Requires the spans of neighbours to meet and those of organs
/// two apart not to (otherwise a third layer would need rules too); returns
/// `None` when they do not.
pub fn contorted_whorl(whorl: &Whorl) -> Option<Arrangement> {
    let n = whorl.count;
    if n < 2 || !whorl.spans_meet(0, 1) || (n > 3 && whorl.spans_meet(0, 2)) {
        return None;
    }
    let overlaps = (0..n)
        .map(|k| Overlap {
            inner: k,
            outer: (k + 1) % n,
        })
        .collect();
    Some(Arrangement {
        organs: whorl.organs(),
        overlaps,
    })
}

/// A phyllotactic spiral (the floral blossom paper §3.2).
#[derive(Debug, Clone, PartialEq)]
pub struct Spiral {
    /// Organ names are `<name>-1`, `<name>-2`, … from the first (outermost)
    /// organ inwards.
    pub name: String,
    /// Index of the organs' template in the flower.
    pub template: usize,
    /// How many organs the spiral holds.
    pub count: usize,
    /// Divergence between consecutive organs, normally [`GOLDEN_ANGLE_DEG`].
    pub divergence_deg: f64,
    /// Base of the first (outermost, oldest) organ.
    pub first_radius: f64,
    /// Height of the first organ's base on the receptacle.
    pub first_height: f64,
    /// Each later organ sits this much nearer the axis and this much higher.
    pub radius_step: f64,
    /// How much higher each later organ's base sits than the one before.
    pub height_step: f64,
    /// Initial joint angle of every organ (positive tilts outwards).
    pub joint_angle_deg: f64,
    /// Half the angle about the axis an organ covers at its widest.
    pub half_span_deg: f64,
}

/// The organs of a spiral and their overlap rules: the earlier (outer)
/// organ of each pair whose spans meet lies outside the later one, as in a
/// rose bud.
pub fn spiral(spiral: &Spiral) -> Arrangement {
    let organs = spiral_organs(spiral);
    match spiral_overlaps(spiral, usize::MAX) {
        Ok(overlaps) | Err(overlaps) => Arrangement { organs, overlaps },
    }
}

/// [`spiral`], or `Err` as soon as it makes more than `limit` overlap
/// rules.
pub fn spiral_within(spiral: &Spiral, limit: usize) -> Result<Arrangement, Arrangement> {
    let organs = spiral_organs(spiral);
    match spiral_overlaps(spiral, limit) {
        Ok(overlaps) => Ok(Arrangement { organs, overlaps }),
        Err(overlaps) => Err(Arrangement { organs, overlaps }),
    }
}

/// The overlap rules of a spiral, later organ inside earlier, ordered by
/// the later organ then the earlier; `Err` with those made so far past
/// `limit`. The organs sorted by azimuth give, by binary search, those
/// within an organ's span, so the work grows with n log n and the rules.
fn spiral_overlaps(spiral: &Spiral, limit: usize) -> Result<Vec<Overlap>, Vec<Overlap>> {
    let azimuth = |k: usize| spiral.divergence_deg * k as f64;
    let reach = 2.0 * spiral.half_span_deg;
    let mut by_azimuth: Vec<(f64, usize)> = (0..spiral.count)
        .map(|k| (azimuth(k).rem_euclid(360.0), k))
        .collect();
    by_azimuth.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let all = !(reach.is_finite() && reach < 180.0 && spiral.divergence_deg.is_finite());
    let mut overlaps = Vec::new();
    let mut earlier = Vec::new();
    for later in 0..spiral.count {
        earlier.clear();
        let mut consider = |k: usize| {
            if k < later && angular_distance_deg(azimuth(k), azimuth(later)) < reach {
                earlier.push(k);
            }
        };
        if all {
            (0..later).for_each(&mut consider);
        } else {
            // The window [a - reach, a + reach] around 360, a little wider
            // for rounding; the exact test above decides.
            let a = azimuth(later).rem_euclid(360.0);
            let slack = 1e-9 * (1.0 + a.abs());
            let mut window = |lo: f64, hi: f64| {
                let start = by_azimuth.partition_point(|e| e.0 < lo);
                let end = by_azimuth.partition_point(|e| e.0 <= hi);
                for &(_, k) in &by_azimuth[start..end.max(start)] {
                    consider(k);
                }
            };
            let (lo, hi) = (a - reach - slack, a + reach + slack);
            window(lo.max(0.0), hi.min(360.0));
            if lo < 0.0 {
                window(lo + 360.0, 360.0);
            }
            if hi > 360.0 {
                window(0.0, hi - 360.0);
            }
        }
        earlier.sort_unstable();
        earlier.dedup();
        overlaps.extend(earlier.iter().map(|&k| Overlap {
            inner: later,
            outer: k,
        }));
        if overlaps.len() > limit {
            return Err(overlaps);
        }
    }
    Ok(overlaps)
}

/// The organs of a spiral, placed.
fn spiral_organs(spiral: &Spiral) -> Vec<Organ> {
    let azimuth = |k: usize| spiral.divergence_deg * k as f64;
    (0..spiral.count)
        .map(|k| Organ {
            name: format!("{}-{}", spiral.name, k + 1),
            template: spiral.template,
            placement: placement(
                azimuth(k).rem_euclid(360.0),
                spiral.first_radius - spiral.radius_step * k as f64,
                spiral.first_height + spiral.height_step * k as f64,
                spiral.joint_angle_deg,
            ),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lily_whorls() -> [Whorl; 2] {
        let petals = Whorl {
            name: "petal".into(),
            template: 0,
            count: 3,
            offset_deg: 0.0,
            radius: 2.0,
            height: 0.0,
            joint_angle_deg: 0.0,
            half_span_deg: 50.0,
        };
        let sepals = Whorl {
            name: "sepal".into(),
            template: 1,
            offset_deg: 60.0,
            radius: 2.8,
            half_span_deg: 45.0,
            ..petals.clone()
        };
        [petals, sepals]
    }

    #[test]
    fn whorl_organs_are_evenly_spaced_and_face_outwards() {
        let [petals, _] = lily_whorls();
        let organs = petals.organs();
        assert_eq!(organs.len(), 3);
        assert_eq!(organs[1].name, "petal-2");
        for organ in &organs {
            let p = organ.placement;
            assert!((p.position.length() - 2.0).abs() < 1e-12);
            // The template's +Z (outwards) is the direction of the base.
            let outwards = p.world_from_template(DVec3::Z, 0.0) - p.position;
            assert!(outwards.dot(p.position.normalize()) > 0.999_999);
        }
        assert!((organs[2].placement.azimuth_deg - 240.0).abs() < 1e-12);
    }

    #[test]
    fn nested_whorls_pair_each_petal_with_its_two_neighbouring_sepals_only() {
        let arrangement = nested_whorls(&lily_whorls());
        assert_eq!(arrangement.organs.len(), 6);
        // Petal 1 (0°) meets sepals at 60° and 300° but not 180°.
        let mut pairs: Vec<(usize, usize)> = arrangement
            .overlaps
            .iter()
            .map(|o| (o.inner, o.outer))
            .collect();
        pairs.sort_unstable();
        assert_eq!(pairs, [(0, 3), (0, 5), (1, 3), (1, 4), (2, 4), (2, 5)]);
    }

    #[test]
    fn contorted_whorl_puts_each_right_side_beneath_the_next_organ() {
        let corolla = Whorl {
            name: "petal".into(),
            template: 0,
            count: 5,
            offset_deg: 0.0,
            radius: 1.5,
            height: 0.0,
            joint_angle_deg: 0.0,
            half_span_deg: 60.0,
        };
        let arrangement = contorted_whorl(&corolla).expect("neighbours overlap");
        let pairs: Vec<(usize, usize)> = arrangement
            .overlaps
            .iter()
            .map(|o| (o.inner, o.outer))
            .collect();
        assert_eq!(pairs, [(0, 1), (1, 2), (2, 3), (3, 4), (4, 0)]);
        // Too narrow to touch, or so wide that three layers meet: refused.
        let narrow = Whorl {
            half_span_deg: 30.0,
            ..corolla.clone()
        };
        assert!(contorted_whorl(&narrow).is_none());
        let wide = Whorl {
            half_span_deg: 80.0,
            ..corolla
        };
        assert!(contorted_whorl(&wide).is_none());
    }

    #[test]
    fn spiral_diverges_by_the_golden_angle_and_later_organs_lie_inside() {
        let arrangement = spiral(&Spiral {
            name: "petal".into(),
            template: 0,
            count: 8,
            divergence_deg: GOLDEN_ANGLE_DEG,
            first_radius: 4.0,
            first_height: 0.0,
            radius_step: 0.3,
            height_step: 0.1,
            joint_angle_deg: 0.0,
            half_span_deg: 40.0,
        });
        let azimuths: Vec<f64> = arrangement
            .organs
            .iter()
            .map(|o| o.placement.azimuth_deg)
            .collect();
        assert!((azimuths[1] - 137.507_764).abs() < 1e-5);
        assert!((azimuths[2] - 275.015_528).abs() < 1e-5);
        assert!(!arrangement.overlaps.is_empty());
        for o in &arrangement.overlaps {
            assert!(o.inner > o.outer);
            let (a, b) = (azimuths[o.inner], azimuths[o.outer]);
            assert!(angular_distance_deg(a, b) < 80.0);
        }
        // Organs 0 and 1 are 137.5° apart: no rule.
        assert!(
            !arrangement
                .overlaps
                .iter()
                .any(|o| (o.inner, o.outer) == (1, 0))
        );
    }
}
