//! The growth function G(t; g, T) of the floral blossom paper
//! eq. (4), and the velocity curve that times the turn of the cells'
//! growth directions.

/// The growth function of eq. (4): a cubic in time whose rate is
/// `g · ΔG / T · (t/T)(1 − t/T)` (eq. (3) with its constant named `g`).
///
/// `G(0) = G_min`; `G(T) = G_min + g · ΔG / 6`, so `g = 6` ends exactly at
/// `G_max` (the paper's eq. (2)), a larger `g` overshoots it and a smaller
/// one stops short.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrowthFunction {
    /// The growth rate `g` (dimensionless; 6 reaches `G_max` at `T`).
    pub g: f64,
    /// The time interval `T` over which the growth runs, in the caller's
    /// time unit (keyframes or seconds); `t` is clamped to `[0, T]`.
    pub duration: f64,
}

impl Default for GrowthFunction {
    /// `g = 6`, `T = 1`: from the bud at `t = 0` to the open state at 1.
    fn default() -> Self {
        GrowthFunction {
            g: 6.0,
            duration: 1.0,
        }
    }
}

impl GrowthFunction {
    /// `G(t; g, T)` for a parameter going from `g_min` to `g_max`, eq. (4):
    /// `−g ΔG t³ / (3T³) + g ΔG t² / (2T²) + G_min`, with `t` clamped to
    /// `[0, T]`.
    pub fn value(&self, t: f64, g_min: f64, g_max: f64) -> f64 {
        g_min + (g_max - g_min) * self.fraction(t)
    }

    /// `(G(t) − G_min) / ΔG`: how far along its way a parameter is at `t`
    /// (0 at `t = 0`, `g / 6` at `T`). A duration that is not positive and
    /// finite counts as reached at once (`g / 6` for every `t`).
    pub fn fraction(&self, t: f64) -> f64 {
        let tau = if self.duration > 0.0 && self.duration.is_finite() {
            (t / self.duration).clamp(0.0, 1.0)
        } else {
            1.0
        };
        self.g * (tau * tau / 2.0 - tau * tau * tau / 3.0)
    }
}

/// How the cells' growth directions turn from the bud's to the open
/// state's over time: the fraction of the spherical linear interpolation
/// reached at time `t` (the paper's "velocity curve").
#[derive(Debug, Clone, PartialEq, Default)]
pub enum VelocityCurve {
    /// The growth function's own timing, scaled to end at 1:
    /// `fraction(t) / fraction(T)` (compatible with it, as the paper asks).
    #[default]
    FollowGrowth,
    /// A curve through `[time / T, fraction]` points, linear between them,
    /// held flat before the first and after the last; the points must be in
    /// increasing time order (see [`VelocityCurve::check`]).
    Points(Vec<[f64; 2]>),
}

impl VelocityCurve {
    /// The slerp fraction at time `t` under `growth`'s duration.
    pub fn fraction(&self, growth: &GrowthFunction, t: f64) -> f64 {
        match self {
            VelocityCurve::FollowGrowth => {
                let end = growth.fraction(growth.duration);
                if end.abs() < f64::EPSILON {
                    0.0
                } else {
                    growth.fraction(t) / end
                }
            }
            VelocityCurve::Points(points) => {
                let tau = if growth.duration > 0.0 && growth.duration.is_finite() {
                    (t / growth.duration).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                piecewise_linear(points, tau)
            }
        }
    }

    /// `Err` with a message naming the first point out of order or not
    /// finite, for a curve typed by a person.
    pub fn check(&self) -> Result<(), String> {
        let VelocityCurve::Points(points) = self else {
            return Ok(());
        };
        if points.is_empty() {
            return Err("a velocity curve needs at least one point".to_owned());
        }
        for (i, p) in points.iter().enumerate() {
            if !p[0].is_finite() || !p[1].is_finite() {
                return Err(format!(
                    "point {} of the velocity curve is not a number",
                    i + 1
                ));
            }
            if i > 0 && p[0] <= points[i - 1][0] {
                return Err(format!(
                    "point {} of the velocity curve is not later than point {}",
                    i + 1,
                    i
                ));
            }
        }
        Ok(())
    }
}

fn piecewise_linear(points: &[[f64; 2]], x: f64) -> f64 {
    let Some(first) = points.first() else {
        return x;
    };
    if x <= first[0] {
        return first[1];
    }
    for pair in points.windows(2) {
        let ([x0, y0], [x1, y1]) = (pair[0], pair[1]);
        if x <= x1 {
            let w = if x1 > x0 { (x - x0) / (x1 - x0) } else { 1.0 };
            return y0 + w * (y1 - y0);
        }
    }
    points[points.len() - 1][1]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eq. (4) written out term by term, as printed in the paper.
    fn eq4(t: f64, g: f64, big_t: f64, g_min: f64, g_max: f64) -> f64 {
        let dg = g_max - g_min;
        -g * dg / (3.0 * big_t.powi(3)) * t.powi(3)
            + g * dg / (2.0 * big_t.powi(2)) * t.powi(2)
            + g_min
    }

    #[test]
    fn the_growth_function_is_eq_4_with_its_end_values() {
        for &(g, big_t) in &[(6.0, 1.0), (6.0, 40.0), (3.0, 10.0), (9.0, 2.5)] {
            let f = GrowthFunction { g, duration: big_t };
            for k in 0..=20 {
                let t = big_t * k as f64 / 20.0;
                let want = eq4(t, g, big_t, 0.7, 2.3);
                assert!(
                    (f.value(t, 0.7, 2.3) - want).abs() < 1e-12,
                    "g {g} T {big_t} t {t}"
                );
            }
            assert_eq!(f.value(0.0, 0.7, 2.3), 0.7);
            let end = 0.7 + g * (2.3 - 0.7) / 6.0;
            assert!((f.value(big_t, 0.7, 2.3) - end).abs() < 1e-12);
            // Clamped outside [0, T].
            assert_eq!(f.value(-1.0, 0.7, 2.3), 0.7);
            assert!((f.value(2.0 * big_t, 0.7, 2.3) - end).abs() < 1e-12);
        }
        // g = 6 is eq. (2): it ends at G_max.
        let f = GrowthFunction {
            g: 6.0,
            duration: 3.0,
        };
        assert!((f.value(3.0, 1.0, 4.0) - 4.0).abs() < 1e-12);
    }

    #[test]
    fn the_growth_rate_is_eq_3() {
        let f = GrowthFunction {
            g: 4.5,
            duration: 7.0,
        };
        let (g_min, g_max) = (1.0, 3.0);
        for k in 1..10 {
            let t = 7.0 * k as f64 / 10.0;
            let h = 1e-6;
            let numeric = (f.value(t + h, g_min, g_max) - f.value(t - h, g_min, g_max)) / (2.0 * h);
            let tau = t / 7.0;
            let analytic = 4.5 * (g_max - g_min) / 7.0 * tau * (1.0 - tau);
            assert!(
                (numeric - analytic).abs() < 1e-7,
                "t {t}: {numeric} vs {analytic}"
            );
        }
    }

    #[test]
    fn the_velocity_curve_ends_at_one_and_follows_its_points() {
        for g in [2.0, 6.0, 10.0] {
            let f = GrowthFunction { g, duration: 5.0 };
            let v = VelocityCurve::FollowGrowth;
            assert_eq!(v.fraction(&f, 0.0), 0.0);
            assert!((v.fraction(&f, 5.0) - 1.0).abs() < 1e-12);
            // Smoothstep shape whatever g: 1/2 at half time.
            assert!((v.fraction(&f, 2.5) - 0.5).abs() < 1e-12);
        }
        let f = GrowthFunction {
            g: 6.0,
            duration: 10.0,
        };
        let v = VelocityCurve::Points(vec![[0.2, 0.0], [0.6, 0.8], [1.0, 1.0]]);
        assert!(v.check().is_ok());
        assert_eq!(v.fraction(&f, 1.0), 0.0);
        assert!((v.fraction(&f, 4.0) - 0.4).abs() < 1e-12);
        assert!((v.fraction(&f, 8.0) - 0.9).abs() < 1e-12);
        assert_eq!(v.fraction(&f, 10.0), 1.0);
        let bad = VelocityCurve::Points(vec![[0.5, 0.0], [0.5, 1.0]]);
        assert!(bad.check().unwrap_err().contains("point 2"));
    }
}
