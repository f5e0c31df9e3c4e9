//! Positions between keyframes: the one interpolation rule of Anthesis
//! (a rule of the project's design: the animation is the linear
//! interpolation of its keyframes), used by the exporters when they resample and by the
//! desktop's timeline when it shows a time between two keyframes.

use glam::DVec3;

/// Where a time, counted in keyframes, falls in a sequence of keyframes:
/// between keyframe `below` and keyframe `above` (the same one at the end
/// or exactly on a keyframe), `fraction` of the way from one to the other.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeyframeBlend {
    /// The keyframe at or before the time.
    pub below: usize,
    /// The keyframe after it (or `below` again).
    pub above: usize,
    /// In `[0, 1)`; 0 when `below == above`.
    pub fraction: f64,
}

impl KeyframeBlend {
    /// Time `time_in_keyframes` (0 = the bud) in a sequence of
    /// `keyframe_count` keyframes; times before the bud or after the last
    /// keyframe are clamped to them, and a time that is not a number is the
    /// bud. `None` when there are no keyframes.
    pub fn at(keyframe_count: usize, time_in_keyframes: f64) -> Option<KeyframeBlend> {
        let last = keyframe_count.checked_sub(1)?;
        let time = if time_in_keyframes.is_nan() {
            0.0
        } else {
            time_in_keyframes.clamp(0.0, last as f64)
        };
        let below = (time.floor() as usize).min(last);
        let fraction = time - below as f64;
        if below == last || fraction <= 0.0 {
            return Some(KeyframeBlend {
                below,
                above: below,
                fraction: 0.0,
            });
        }
        Some(KeyframeBlend {
            below,
            above: below + 1,
            fraction,
        })
    }

    /// The positions `fraction` of the way from `below` (keyframe
    /// [`KeyframeBlend::below`]'s) to `above` (keyframe
    /// [`KeyframeBlend::above`]'s), point by point.
    pub fn positions(&self, below: &[DVec3], above: &[DVec3]) -> Vec<DVec3> {
        if self.fraction == 0.0 {
            return below.to_vec();
        }
        below
            .iter()
            .zip(above)
            .map(|(a, b)| a.lerp(*b, self.fraction))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_fall_between_neighbouring_keyframes_and_clamp_at_the_ends() {
        let blend = |time| KeyframeBlend::at(3, time).expect("keyframes");
        let at = |below, above, fraction| KeyframeBlend {
            below,
            above,
            fraction,
        };
        assert_eq!(blend(0.0), at(0, 0, 0.0));
        assert_eq!(blend(0.25), at(0, 1, 0.25));
        assert_eq!(blend(1.0), at(1, 1, 0.0));
        assert_eq!(blend(1.5), at(1, 2, 0.5));
        assert_eq!(blend(2.0), at(2, 2, 0.0));
        assert_eq!(blend(7.0), at(2, 2, 0.0));
        assert_eq!(blend(-1.0), at(0, 0, 0.0));
        assert_eq!(blend(f64::NAN), at(0, 0, 0.0));
        assert_eq!(blend(f64::INFINITY), at(2, 2, 0.0));
        assert_eq!(KeyframeBlend::at(0, 0.0), None);
        assert_eq!(KeyframeBlend::at(1, 0.7), Some(at(0, 0, 0.0)));
    }

    #[test]
    fn positions_move_in_a_straight_line() {
        let below = [DVec3::ZERO, DVec3::X];
        let above = [DVec3::new(4.0, 0.0, 0.0), DVec3::new(1.0, 8.0, 0.0)];
        let blend = KeyframeBlend::at(2, 0.25).expect("keyframes");
        assert_eq!(
            blend.positions(&below, &above),
            [DVec3::new(1.0, 0.0, 0.0), DVec3::new(1.0, 2.0, 0.0)]
        );
        let on_keyframe = KeyframeBlend::at(2, 1.0).expect("keyframes");
        assert_eq!(on_keyframe.positions(&above, &above), above);
    }
}
