//! Held-out validation of the 1:10 models ([`super::disc_model`]): refit without some nodes of
//! [T002 Tables 3.3-3.5] and compare the coefficients there with the table. Relative errors
//! are taken where the coefficient is not ~0; lift and torque at φ = 0° and 90° (which vanish
//! by symmetry, printed as 0.00-0.08) get absolute errors.

use super::correlations::Coefficients;
use super::disc_model::{DiscMethod, DiscModel, Variant, table_coefficient};
use super::disc_table::{PHI_DEG, re_e};
use serde::{Deserialize, Serialize};

const NX: usize = 14;
const NY: usize = 19;

/// Which nodes a validation holds out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Split {
    /// Each interior Re column in turn (12 refits).
    LeaveOneColumnOut,
    /// Each interior angle row in turn (17 refits).
    LeaveOneRowOut,
    /// Columns 1, 3, …, 11 together (one refit on the 8 others).
    EveryOtherColumn,
    /// Rows 5°, 15°, …, 85° together (one refit on the 10 others).
    EveryOtherRow,
}

/// Held-out errors of one method and split, per coefficient (drag, lift, torque).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct HeldOut {
    /// Largest relative error where the coefficient is not ~0 (lift and torque: φ ≠ 0°, 90°).
    pub max_relative: [f64; 3],
    /// Mean relative error over the same nodes.
    pub mean_relative: [f64; 3],
    /// Largest absolute error of C at φ = 0° and 90° (against the printed value).
    pub max_absolute_at_symmetry: [f64; 3],
    /// Number of held-out nodes.
    pub nodes: usize,
    /// (φ \[deg\], Re_e) of the node with the largest relative error, per coefficient.
    pub worst_node: [(f64, f64); 3],
}

/// Held-out errors of `method` under `split`: refit without the held-out nodes, compare C
/// there with the table.
pub fn held_out(method: DiscMethod, split: Split) -> HeldOut {
    held_out_variant(method, Variant::default(), split)
}

/// [`held_out`] for another parametrisation.
pub fn held_out_variant(method: DiscMethod, variant: Variant, split: Split) -> HeldOut {
    let all_c: Vec<usize> = (0..NX).collect();
    let all_r: Vec<usize> = (0..NY).collect();
    // (kept columns, kept rows, held-out nodes (row, column))
    type Fold = (Vec<usize>, Vec<usize>, Vec<(usize, usize)>);
    let folds: Vec<Fold> = match split {
        Split::LeaveOneColumnOut => (1..NX - 1)
            .map(|j| {
                let cols = all_c.iter().copied().filter(|&c| c != j).collect();
                (cols, all_r.clone(), all_r.iter().map(|&i| (i, j)).collect())
            })
            .collect(),
        Split::LeaveOneRowOut => (1..NY - 1)
            .map(|i| {
                let rows = all_r.iter().copied().filter(|&r| r != i).collect();
                (all_c.clone(), rows, all_c.iter().map(|&j| (i, j)).collect())
            })
            .collect(),
        Split::EveryOtherColumn => {
            let out: Vec<usize> = (1..NX - 1).step_by(2).collect();
            let cols = all_c.iter().copied().filter(|c| !out.contains(c)).collect();
            let nodes = out
                .iter()
                .flat_map(|&j| all_r.iter().map(move |&i| (i, j)))
                .collect();
            vec![(cols, all_r.clone(), nodes)]
        }
        Split::EveryOtherRow => {
            let out: Vec<usize> = (1..NY - 1).step_by(2).collect();
            let rows = all_r.iter().copied().filter(|r| !out.contains(r)).collect();
            let nodes = out
                .iter()
                .flat_map(|&i| all_c.iter().map(move |&j| (i, j)))
                .collect();
            vec![(all_c.clone(), rows, nodes)]
        }
    };
    let mut acc = Accumulator::default();
    for (cols, rows, nodes) in folds {
        let model = DiscModel::fit_variant(method, variant, &cols, &rows);
        for (i, j) in nodes {
            let c = model.coefficients(re_e(j), PHI_DEG[i].to_radians());
            acc.add(i, j, [c.drag, c.lift, c.torque]);
        }
    }
    acc.finish()
}

/// Errors of any coefficient model `f(Re_e, φ) -> C` against every table node.
#[allow(clippy::needless_range_loop)] // (row, column) indices name the table node
pub fn errors_against_table(f: impl Fn(f64, f64) -> Coefficients) -> HeldOut {
    let mut acc = Accumulator::default();
    for i in 0..NY {
        for j in 0..NX {
            let c = f(re_e(j), PHI_DEG[i].to_radians());
            acc.add(i, j, [c.drag, c.lift, c.torque]);
        }
    }
    acc.finish()
}

#[derive(Default)]
struct Accumulator {
    out: HeldOut,
    sum: [f64; 3],
    count: [usize; 3],
}

impl Accumulator {
    fn add(&mut self, i: usize, j: usize, c: [f64; 3]) {
        self.out.nodes += 1;
        let edge = i == 0 || i == NY - 1;
        for (q, &model) in c.iter().enumerate() {
            let table = table_coefficient(q, i, j);
            if q > 0 && edge {
                let e = (model - table).abs();
                let m = &mut self.out.max_absolute_at_symmetry[q];
                *m = if e.is_nan() { f64::INFINITY } else { m.max(e) };
            } else {
                let e = (model - table).abs() / table.abs();
                let e = if e.is_nan() { f64::INFINITY } else { e };
                if e > self.out.max_relative[q] {
                    self.out.max_relative[q] = e;
                    self.out.worst_node[q] = (PHI_DEG[i], re_e(j));
                }
                self.sum[q] += e;
                self.count[q] += 1;
            }
        }
    }

    fn finish(mut self) -> HeldOut {
        for q in 0..3 {
            self.out.mean_relative[q] = self.sum[q] / self.count[q].max(1) as f64;
        }
        self.out
    }
}
