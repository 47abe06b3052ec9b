//! Contacts that must never be crossed: capture on a fibre along the swept segment of a step,
//! and hard-core overlap removal between particles.
//!
//! **Capture** ([T000 §6.3]: a particle that comes into contact with the cylinder is captured
//! and fixed). A step moves a particle along the segment `x0 → x1`; the particle is captured at
//! the first point of that segment whose distance to a fibre is at most its radius. The distance
//! to a solid cylinder is 1-Lipschitz, so bisection with the bound
//! `min_[s0,s1] d ≥ (d(s0) + d(s1) − |x(s1) − x(s0)|) / 2` finds that point without sampling
//! gaps (D-000-10 in docs/references.md: at the thesis's steps a 25 nm particle moves more than its radius).
//!
//! **Hard cores** (an overlap-safe alternative to the stiff Mie potential, D-000-10,
//! in the spirit of Heyes and Melrose, J. Non-Newtonian Fluid Mech. 46, 1 (1993)): after a move,
//! every overlapping pair is pushed apart along its line of centres to contact, shared equally
//! when both move and taken wholly by the mobile one otherwise; Gauss-Seidel sweeps in a fixed
//! order until no overlap exceeds `1e-12 σ`.

use glam::DVec3;

use super::cells::CellList;
use crate::field::CylinderSource;

/// Resolution of the capture search, relative to the particle radius.
const CAPTURE_RESOLUTION: f64 = 1e-6;

/// The first point of the segment `x0 → x1` where a sphere of radius `a` touches one of
/// `fibres`: `(fibre index, contact position)`. The position is at distance `a` from the fibre
/// (to the search resolution).
///
/// ```
/// use glam::DVec3;
/// use magsep_systems::brownian::contact::swept_capture;
/// use magsep_systems::field::CylinderSource;
/// let fibre = CylinderSource::new(DVec3::ZERO, DVec3::Z, 1.0, 5.0, DVec3::ZERO);
/// // a particle of radius 0.1 jumping right across the fibre is caught on the near side
/// let (k, p) = swept_capture(&[fibre], DVec3::new(-3.0, 0.0, 0.0), DVec3::new(3.0, 0.0, 0.0), 0.1).unwrap();
/// assert_eq!(k, 0);
/// assert!((p.x + 1.1).abs() < 1e-6);
/// ```
pub fn swept_capture(
    fibres: &[CylinderSource],
    x0: DVec3,
    x1: DVec3,
    a: f64,
) -> Option<(usize, DVec3)> {
    swept_capture_gap(fibres, x0, x1, a).0
}

/// A lower bound `gap` of a particle's gap (distance to the nearest fibre minus its radius)
/// at the position `at` \[m\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GapBound {
    /// Where the bound holds \[m\].
    pub at: DVec3,
    /// The bound \[m\].
    pub gap: f64,
}

/// [`swept_capture`] with a memo of the particle's gap: when `bound` holds at `x0` and exceeds
/// the segment's length, the segment cannot touch a fibre (the gap is 1-Lipschitz), so
/// nothing is computed and the bound moves to `x1` reduced by the length; otherwise the exact
/// search runs and leaves the exact gap at `x1` (or `None` after a capture). The result is
/// that of [`swept_capture`]. Far from the fibres this skips almost every distance evaluation.
pub fn swept_capture_cached(
    fibres: &[CylinderSource],
    x0: DVec3,
    x1: DVec3,
    a: f64,
    bound: &mut Option<GapBound>,
) -> Option<(usize, DVec3)> {
    let len = (x1 - x0).length();
    if let Some(b) = *bound
        && b.at == x0
        && b.gap - len > 0.0
    {
        *bound = Some(GapBound {
            at: x1,
            gap: b.gap - len,
        });
        return None;
    }
    let (hit, gap) = swept_capture_gap(fibres, x0, x1, a);
    *bound = match hit {
        None if gap.is_finite() => Some(GapBound { at: x1, gap }),
        _ => None,
    };
    hit
}

/// [`swept_capture`], and the exact gap at `x1` (the smallest over the fibres; meaningful
/// only when nothing is captured; infinite without fibres).
fn swept_capture_gap(
    fibres: &[CylinderSource],
    x0: DVec3,
    x1: DVec3,
    a: f64,
) -> (Option<(usize, DVec3)>, f64) {
    let len = (x1 - x0).length();
    let mut best: Option<(f64, usize)> = None;
    let mut end_gap = f64::INFINITY;
    for (k, f) in fibres.iter().enumerate() {
        let gap = |s: f64| f.distance(x0 + (x1 - x0) * s) - a;
        let g0 = gap(0.0);
        if g0 <= 0.0 {
            best = Some((0.0, k));
            break;
        }
        let g1 = gap(1.0);
        end_gap = end_gap.min(g1);
        if g1 > 0.0 && 0.5 * (g0 + g1 - len) > 0.0 {
            continue;
        }
        // depth-first bisection for the first touching s
        let mut stack = vec![(0.0f64, 1.0f64, g0, g1)];
        while let Some((s0, s1, d0, d1)) = stack.pop() {
            if best.is_some_and(|(s, _)| s <= s0) {
                continue;
            }
            if 0.5 * (d0 + d1 - len * (s1 - s0)) > 0.0 {
                continue;
            }
            if d1 <= 0.0 && len * (s1 - s0) < CAPTURE_RESOLUTION * a {
                best = Some((s1, k));
                continue;
            }
            if len * (s1 - s0) < CAPTURE_RESOLUTION * a {
                continue;
            }
            let sm = 0.5 * (s0 + s1);
            let dm = gap(sm);
            if dm <= 0.0 && len * (sm - s0) < CAPTURE_RESOLUTION * a {
                best = Some((sm, k));
                continue;
            }
            stack.push((sm, s1, dm, d1));
            stack.push((s0, sm, d0, dm));
        }
    }
    let Some((s, k)) = best else {
        return (None, end_gap);
    };
    let p = x0 + (x1 - x0) * s;
    // snap onto the contact sphere: distance exactly a along the normal
    let c = fibres[k].closest_point(p);
    let n = p - c;
    let p = if n.length() > 0.0 {
        c + n * (a / n.length())
    } else {
        p
    };
    (Some((k, p)), end_gap)
}

/// Push overlapping pairs apart (see the module header). `mobile[i]` particles move; pairs of
/// two fixed particles are left alone. Returns the number of sweeps (0: nothing overlapped).
pub fn remove_overlaps(
    x: &mut [DVec3],
    radii: &[f64],
    mobile: &[bool],
    max_sweeps: usize,
) -> usize {
    let amax = radii.iter().copied().fold(0.0, f64::max);
    if amax == 0.0 || x.len() < 2 {
        return 0;
    }
    for sweep in 0..max_sweeps {
        let cells = CellList::build(x, 2.0 * amax, |_| true);
        let mut moved = false;
        for i in 0..x.len() {
            let mut pairs = Vec::new();
            cells.for_each_neighbour(x, i, 2.0 * amax, |j, _| {
                if j > i {
                    pairs.push(j)
                }
            });
            for j in pairs {
                if !(mobile[i] || mobile[j]) {
                    continue;
                }
                let d = x[i] - x[j];
                let sigma = radii[i] + radii[j];
                let r = d.length();
                if r >= sigma * (1.0 - 1e-12) {
                    continue;
                }
                let n = if r > 0.0 { d / r } else { DVec3::Z };
                // a hair beyond contact so rounding cannot leave an overlap
                let push = (sigma - r) + 1e-12 * sigma;
                let (wi, wj) = match (mobile[i], mobile[j]) {
                    (true, true) => (0.5, 0.5),
                    (true, false) => (1.0, 0.0),
                    _ => (0.0, 1.0),
                };
                x[i] += n * (push * wi);
                x[j] -= n * (push * wj);
                moved = true;
            }
        }
        if !moved {
            return sweep;
        }
    }
    max_sweeps
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    #[test]
    fn the_gap_memo_changes_no_capture_and_skips_far_segments() {
        // random walks (steps of 0.02-0.2) from far away towards two fibres: the cached search
        // returns what the plain one does at every step, and far from the fibres it computes
        // nothing (its bound drops by exactly the step length)
        let fibres = [
            CylinderSource::new(DVec3::ZERO, DVec3::Z, 1.0, 2.0, DVec3::ZERO),
            CylinderSource::new(DVec3::new(3.0, 0.0, 0.0), DVec3::X, 0.5, 1.0, DVec3::ZERO),
        ];
        let a = 0.05;
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(9);
        let (mut skipped, mut captured) = (0, 0);
        for walk in 0..60 {
            let mut x = DVec3::new(8.0, 6.0 - 0.2 * walk as f64, 4.0);
            let mut bound = None;
            for _ in 0..400 {
                let step = 0.02 + 0.18 * rng.random::<f64>();
                let dir = (DVec3::new(1.5, 0.0, 0.0) - x).normalize_or_zero()
                    + DVec3::new(rng.random(), rng.random(), rng.random())
                    - 0.5;
                let x1 = x + dir.normalize_or_zero() * step;
                let before = bound;
                let cached = swept_capture_cached(&fibres, x, x1, a, &mut bound);
                assert_eq!(cached, swept_capture(&fibres, x, x1, a));
                if let Some(b) = before
                    && b.at == x
                    && b.gap > (x1 - x).length()
                {
                    skipped += 1;
                    assert_eq!(bound.unwrap().gap, b.gap - (x1 - x).length());
                    let exact = fibres
                        .iter()
                        .map(|f| f.distance(x1) - a)
                        .fold(f64::MAX, f64::min);
                    assert!(bound.unwrap().gap <= exact, "the bound exceeds the gap");
                }
                if let Some((_, p)) = cached {
                    captured += 1;
                    assert!(bound.is_none());
                    x = p;
                    break;
                }
                x = x1;
            }
        }
        assert!(skipped > 1000, "skipped {skipped}");
        assert!(captured > 20, "captured {captured}");
    }

    #[test]
    fn capture_finds_grazing_and_end_face_contacts() {
        let f = CylinderSource::new(DVec3::ZERO, DVec3::Z, 1.0, 2.0, DVec3::ZERO);
        let a = 0.05;
        // grazing pass: the segment's closest approach to the lateral surface is 1.04 < 1.05
        let y = 1.04;
        let hit = swept_capture(
            std::slice::from_ref(&f),
            DVec3::new(-3.0, y, 0.0),
            DVec3::new(3.0, y, 0.0),
            a,
        );
        let (_, p) = hit.expect("grazing contact missed");
        assert!((f.distance(p) - a).abs() < 1e-6 * a);
        assert!(p.x < 0.0, "first contact is on the entry side: {p}");
        // a miss by a hair
        let y = 1.0 + a + 1e-4;
        assert!(
            swept_capture(
                std::slice::from_ref(&f),
                DVec3::new(-3.0, y, 0.0),
                DVec3::new(3.0, y, 0.0),
                a
            )
            .is_none()
        );
        // falling onto the end face
        let (_, p) = swept_capture(
            std::slice::from_ref(&f),
            DVec3::new(0.3, 0.0, 4.0),
            DVec3::new(0.3, 0.0, 1.0),
            a,
        )
        .unwrap();
        assert!((p.z - 2.05).abs() < 1e-6);
        // brute force on random segments
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(2);
        for _ in 0..2000 {
            let mut pt = || {
                DVec3::new(
                    rng.random_range(-2.0..2.0),
                    rng.random_range(-2.0..2.0),
                    rng.random_range(-3.0..3.0),
                )
            };
            let (x0, x1) = (pt(), pt());
            if f.distance(x0) <= a {
                continue;
            }
            let brute = (0..=20000)
                .map(|k| k as f64 / 20000.0)
                .find(|&s| f.distance(x0 + (x1 - x0) * s) <= a);
            let got = swept_capture(std::slice::from_ref(&f), x0, x1, a);
            match (brute, got) {
                (Some(s), Some((_, p))) => {
                    let sp = (p - x0).length() / (x1 - x0).length();
                    assert!(sp <= s + 1e-6, "later than brute force: {sp} vs {s}")
                }
                (None, Some((_, p))) => {
                    // a touch between samples only: must be a real one
                    assert!((f.distance(p) - a).abs() < 1e-5)
                }
                (Some(s), None) => panic!("missed contact at s = {s}: {x0} -> {x1}"),
                (None, None) => {}
            }
        }
    }

    #[test]
    fn hard_cores_leave_no_overlap_and_fixed_particles_stay() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(4);
        let n = 300;
        let mut x: Vec<DVec3> = (0..n)
            .map(|_| {
                DVec3::new(
                    rng.random_range(0.0..8.0),
                    rng.random_range(0.0..8.0),
                    rng.random_range(0.0..8.0),
                )
            })
            .collect();
        let radii: Vec<f64> = (0..n).map(|i| if i % 3 == 0 { 0.7 } else { 0.5 }).collect();
        let mobile: Vec<bool> = (0..n).map(|i| i % 10 != 0).collect();
        let fixed: Vec<DVec3> = x.clone();
        let sweeps = remove_overlaps(&mut x, &radii, &mobile, 10_000);
        assert!(sweeps > 0 && sweeps < 10_000, "{sweeps}");
        for i in 0..n {
            if !mobile[i] {
                assert_eq!(x[i], fixed[i]);
            }
            for j in i + 1..n {
                if mobile[i] || mobile[j] {
                    let s = radii[i] + radii[j];
                    assert!((x[i] - x[j]).length() >= s * (1.0 - 1e-12), "{i} {j}");
                }
            }
        }
    }
}
