//! Starting points for the Newton solve (replacing the point-sampled surfaces of [T000 §4.4.2]):
//! GJK (separated pairs: closest points) or EPA (penetrating pairs) of parry3d-f64 on the
//! analytic support maps gives a direction n in a's frame; the seeds are the support points
//! of a along n and of b along -n, which lie exactly on the surfaces with anti-parallel
//! normals. g(n) = h_a(n) + h_b(-n) - d.n, the support-function overlap in that direction,
//! is an upper bound of the true overlap min_u g(u); it is the GJK/EPA-only answer and the
//! bound the Newton solution must not exceed. The centre line is kept instead when its g is
//! smaller (EPA occasionally returns a degenerate face with an arbitrary normal).

use std::cell::RefCell;

use glam::{DQuat, DVec3};
use parry3d_f64::math::Pose;
use parry3d_f64::query::epa::EPA;
use parry3d_f64::query::gjk::{self, CsoPoint, GJKResult, VoronoiSimplex};

use super::newton::PairFrame;
use super::prepared::Prepared;

thread_local! {
    static EPA_WORKSPACE: RefCell<EPA> = RefCell::new(EPA::new());
}

/// What GJK/EPA returned.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum SeedKind {
    /// Separated or touching (GJK closest points).
    Gjk,
    /// Penetrating (EPA).
    Epa,
    /// Gap above the band (GJK stopped early).
    Beyond,
    /// EPA or GJK failed: the centre line is used.
    Failed,
}

/// A GJK/EPA seed: a-frame unit normal, support points and their overlap estimate.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Seed {
    pub kind: SeedKind,
    /// Unit normal in a's frame.
    pub n_a: DVec3,
    pub s_a: DVec3,
    pub s_b: DVec3,
    /// Support-function value along n_a: an upper bound of the overlap.
    pub overlap: f64,
    /// parry's witness points and normal (a's frame), when it returned them.
    pub raw: Option<(DVec3, DVec3, DVec3)>,
}

pub(crate) fn seed_from(
    pa: &Prepared,
    pb: &Prepared,
    pair: &PairFrame,
    n_a: DVec3,
) -> (DVec3, DVec3, f64) {
    let n_b = pair.r * n_a;
    let s_a = pa.support(n_a);
    let s_b = pb.support(-n_b);
    let overlap = (pair.r * s_a + pair.c - s_b).dot(n_b);
    (s_a, s_b, overlap)
}

/// GJK (EPA when penetrating) seed. GJK stops once the gap exceeds `cutoff` and, unless
/// `exact`, as soon as the pair is known to be separated by less than `cutoff`.
pub(crate) fn gjk_epa(
    pa: &Prepared,
    pb: &Prepared,
    pair: &PairFrame,
    qab: DQuat,
    d_a: DVec3,
    cutoff: f64,
    exact: bool,
) -> Seed {
    let pos12 = Pose::from_parts(d_a, qab);
    let centre_line = d_a.try_normalize().unwrap_or(DVec3::X);
    let mut simplex = VoronoiSimplex::new();
    simplex.reset(CsoPoint::from_shapes(&pos12, pa, pb, centre_line));
    let (kind, dir, raw) = match gjk::closest_points(&pos12, pa, pb, cutoff, exact, &mut simplex) {
        GJKResult::ClosestPoints(p1, p2, n) => (SeedKind::Gjk, n, Some((p1, p2, n))),
        GJKResult::Proximity(n) => (SeedKind::Gjk, n, None),
        GJKResult::NoIntersection(n) => (SeedKind::Beyond, n, None),
        GJKResult::Intersection => {
            let epa = EPA_WORKSPACE.with(|e| {
                e.try_borrow_mut()
                    .ok()
                    .and_then(|mut e| e.closest_points(&pos12, pa, pb, &simplex))
            });
            match epa {
                Some((p1, p2, n)) => (SeedKind::Epa, n, Some((p1, p2, n))),
                None => (SeedKind::Failed, centre_line, None),
            }
        }
    };
    let (mut kind, mut n_a) = match dir.try_normalize() {
        Some(n) => (kind, n),
        None => (SeedKind::Failed, centre_line),
    };
    let (mut s_a, mut s_b, mut overlap) = seed_from(pa, pb, pair, n_a);
    if kind == SeedKind::Beyond && overlap > -cutoff {
        // GJK gave up (iteration limit) rather than certifying the cutoff
        kind = SeedKind::Failed;
    }
    if kind != SeedKind::Failed {
        // EPA occasionally returns a degenerate face (zero depth, arbitrary normal): keep
        // whichever of its direction and the centre line has the smaller support-function
        // value (both are upper bounds of the overlap, the smaller one is closer)
        let (ca, cb, co) = seed_from(pa, pb, pair, centre_line);
        if co < overlap {
            (n_a, s_a, s_b, overlap) = (centre_line, ca, cb, co);
        }
    } else {
        n_a = centre_line;
        (s_a, s_b, overlap) = seed_from(pa, pb, pair, n_a);
    }
    Seed {
        kind,
        n_a,
        s_a,
        s_b,
        overlap,
        raw,
    }
}
