//! Sweeps by cells: the Gauss-Seidel sweep of [`super::sweep`] in an order that runs on many
//! threads at once and is still one serial order, the same for any thread count.
//!
//! **Order.** The periodic axes that hold at least four cells of width `w` = the list's
//! cut-off plus its skin are cut into an even number of cells each (the longest axis first,
//! further axes only until a colour has [`MIN_CELLS_PER_COLOUR`] cells), on a grid shifted by
//! a random offset drawn anew each sweep. A cell's colour is the parity of its coordinates
//! (a checkerboard: up to 8 colours). The sweep visits the colours in turn, the cells of a
//! colour in index order, and the particles of a cell in the shuffled order of the sweep. Two
//! cells of one colour are at least one cell width apart, so no listed pair joins them (a
//! listed pair was within the cut-off at the build and each end has moved by less than half
//! the skin since): the moves in one cell read no pose that a move in another cell of its
//! colour writes, and the cells of a colour can run at once, each serially, with the result
//! of the serial order. The particles still to move have not moved since they were put in
//! their cells (one move per particle and sweep), so two of them in different cells of a
//! colour are at least the narrowest cell's width apart: when that width is at least the
//! list's present reach (a rebuild within the sweep may lengthen it), no listed pair can join
//! them. Otherwise it is checked on the list itself before each run; if a listed pair does
//! join two such cells, the colour's cells run one after the other instead. Within a run the
//! leader takes cells from the first and the helpers from the last (`Team::map_sided`): the
//! particles' dense order follows the cells' numbering, so each processor keeps the data of
//! its part of the box in its cache from phase to phase.
//!
//! **Runs.** A cell's moves are computed against the state at the start of the run, with the
//! poses of the cell's own earlier moves laid over it ([`super::contacts_with`]; the tracker's
//! certificates count those moves' travels, as they will after the write-back), and written
//! back (Newton starts, poses, the list's displacement bounds, the tracker's versions) cell by
//! cell in the serial order after the run. A cell stops after the move that takes its particle
//! past the list's skin (the move the serial sweep would make just before a rebuild); the
//! other cells of the run finish, the list is rebuilt and the stopped cells go on. The attempt
//! budget is tested before each run (a run may overshoot it by the moves of one colour).
//!
//! The order differs from the plain shuffled order of [`super::sweep`], so packings differ
//! from that sweep's (statistically the same: the same rule, another Gauss-Seidel order).
//! Boxes too small for four cells along any periodic axis keep the plain order, and so do the
//! rules that draw random numbers.

use glam::{DQuat, DVec3};
use rand::{Rng, RngExt};

use super::{OverlapTracker, Proposal, SweepCount, commit_counted, contacts_with, unused_rng};
use crate::buckets::bucket_sort;
use crate::packing::moves::{MoveRule, overlap_removal_move};
use crate::packing::neighbour::NeighbourList;
use crate::packing::state::PackingState;
use crate::par::team::Team;

/// Axes are split until a colour has at least this many cells (more, smaller tasks balance
/// the threads better; fewer colours mean fewer joins per sweep).
pub const MIN_CELLS_PER_COLOUR: usize = 8;

/// Most cells along one axis.
const MAX_CELLS_PER_AXIS: usize = 256;

const NONE: u32 = u32::MAX;

/// The checkerboard of one sweep (see the module header).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepCells {
    /// Cells per axis (1: the axis is not cut).
    pub n: [usize; 3],
    /// Grid offset per axis / D.
    pub offset: DVec3,
    /// Box edges / D.
    pub edges: DVec3,
}

impl SweepCells {
    /// The cells for `state` and its built `list`, with offsets drawn from `rng`; None (and no
    /// number drawn) when no periodic axis holds four cells.
    pub fn choose(state: &PackingState, list: &NeighbourList, rng: &mut impl Rng) -> Option<Self> {
        let width = list.centre_range() + list.skin;
        let periodic = state.periodic();
        let counts: [usize; 3] = std::array::from_fn(|a| {
            let c = (state.edges[a] / width).floor();
            if periodic[a] && c.is_finite() && c >= 4.0 {
                (c as usize).min(MAX_CELLS_PER_AXIS) & !1
            } else {
                0
            }
        });
        let mut axes: Vec<usize> = (0..3).filter(|&a| counts[a] >= 4).collect();
        if axes.is_empty() {
            return None;
        }
        axes.sort_by_key(|&a| std::cmp::Reverse(counts[a]));
        let mut n = [1usize; 3];
        let mut per_colour = 1;
        for a in axes {
            if per_colour >= MIN_CELLS_PER_COLOUR {
                break;
            }
            n[a] = counts[a];
            per_colour *= counts[a] / 2;
        }
        let offset = DVec3::from_array(std::array::from_fn(|a| {
            if n[a] > 1 {
                rng.random::<f64>() * state.edges[a] / n[a] as f64
            } else {
                0.0
            }
        }));
        Some(Self {
            n,
            offset,
            edges: state.edges,
        })
    }

    /// The narrowest cell's width along the cut axes / D (infinite when no axis is cut).
    pub fn min_width(&self) -> f64 {
        (0..3)
            .filter(|&a| self.n[a] > 1)
            .map(|a| self.edges[a] / self.n[a] as f64)
            .fold(f64::INFINITY, f64::min)
    }

    /// The (colour, cell index) of a centre `x`.
    pub fn locate(&self, x: DVec3) -> (u32, u32) {
        let mut colour = 0;
        let mut cell = 0;
        for a in (0..3).rev() {
            let n = self.n[a];
            let c = if n > 1 {
                let u = (x[a] - self.offset[a]) / self.edges[a];
                (((u - u.floor()) * n as f64).floor() as usize).min(n - 1)
            } else {
                0
            };
            colour |= ((c & 1) as u32) << a;
            cell = cell * n as u32 + c as u32;
        }
        (colour, cell)
    }

    /// The sweep's queues: per colour (in order), per cell of it (in index order), the
    /// particles of `order` in that cell, in `order`'s order ([`Queues::colours`]).
    pub fn queues(&self, state: &PackingState, order: &[usize]) -> Queues {
        // a counting sort by cell (stable, so in `order`'s order within a cell) into one
        // vector, then the non-empty cells of each colour in index order: a few vectors per
        // sweep instead of one per cell (those were a fifth of the serial time on two threads)
        let ncells = self.n.iter().product::<usize>();
        let mut colour_of = vec![0u8; ncells];
        let cell_of: Vec<usize> = order
            .iter()
            .map(|&i| {
                let (colour, cell) = self.locate(state.positions[i]);
                colour_of[cell as usize] = colour as u8;
                cell as usize
            })
            .collect();
        let (mut start, mut slots) = (Vec::new(), Vec::new());
        bucket_sort(&cell_of, ncells, &mut start, &mut slots);
        let particles = slots.iter().map(|&k| order[k as usize]).collect();
        let mut colours: Vec<Vec<(usize, usize)>> = vec![Vec::new(); 8];
        for c in 0..ncells {
            if start[c + 1] > start[c] {
                colours[colour_of[c] as usize].push((start[c], start[c + 1]));
            }
        }
        colours.retain(|cells| !cells.is_empty());
        Queues { particles, colours }
    }
}

/// The queues of one sweep ([`SweepCells::queues`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Queues {
    /// The particles of the sweep, cell after cell.
    particles: Vec<usize>,
    /// Per colour (in order, non-empty ones only): its non-empty cells' ranges of
    /// `particles`, in index order.
    colours: Vec<Vec<(usize, usize)>>,
}

impl Queues {
    /// Per colour in order: the queues of its non-empty cells, in index order.
    pub fn colours(&self) -> impl Iterator<Item = Vec<&[usize]>> + '_ {
        self.colours
            .iter()
            .map(|cells| cells.iter().map(|&(a, b)| &self.particles[a..b]).collect())
    }
}

/// The moves of one cell in one run (see the module header).
struct CellRun {
    /// Every visited particle with its proposal, in order (a proposal without displacement
    /// still carries the Newton starts to store).
    moves: Vec<(usize, Proposal)>,
    /// Queue position reached (the queue's length unless the cell stopped at the skin).
    end: usize,
}

/// Marks of the particles still to move in a run: cell and position in its queue.
struct Marks {
    cell: Vec<u32>,
    slot: Vec<u32>,
}

/// Move the particles of `order` once each (those still overlapping) in the order of `cells`,
/// until `attempts` reaches `budget` at the start of a run; rebuilds the list when needed.
/// The same result for any number of rayon threads (module header).
#[allow(clippy::too_many_arguments)]
pub fn sweep_cells(
    state: &mut PackingState,
    list: &mut NeighbourList,
    tracker: &mut OverlapTracker,
    order: &[usize],
    cells: &SweepCells,
    rule: MoveRule,
    tol: f64,
    budget: u64,
    attempts: &mut u64,
    team: &Team<'_>,
) -> SweepCount {
    let mut count = SweepCount::default();
    let mut marks = Marks {
        cell: vec![NONE; state.len()],
        slot: vec![NONE; state.len()],
    };
    let all = cells.queues(state, order);
    for queues in all.colours() {
        let mut pos = vec![0usize; queues.len()];
        loop {
            let live: Vec<usize> = (0..queues.len())
                .filter(|&c| pos[c] < queues[c].len())
                .collect();
            if live.is_empty() {
                break;
            }
            if *attempts >= budget {
                return count;
            }
            if list.needs_rebuild() {
                list.build(state);
            }
            mark(&mut marks, &queues, &live, &pos);
            let groups = if cells.min_width() >= list.centre_range() + list.skin {
                // no listed pair can join two cells of a colour (module header)
                vec![live.clone()]
            } else {
                groups(list, &marks, &queues, &live, &pos)
            };
            for g in groups {
                let (s, l, t, m) = (&*state, &*list, &*tracker, &marks);
                let run = |&c: &usize| run_cell(s, l, t, queues[c], pos[c], c as u32, m, rule, tol);
                // in cell order, the leader from the first cell and the helpers from the last
                // (cells are numbered along the axes the particles' dense order follows, so
                // each processor keeps its part of the box: see `Team::map_sided`)
                let results = team.map_sided(g.len(), |y| run(&g[y]));
                let mut stopped = false;
                for (&c, r) in g.iter().zip(results) {
                    for (i, p) in &r.moves {
                        commit_counted(state, list, tracker, *i, p, attempts, &mut count);
                    }
                    stopped |= r.end < queues[c].len();
                    pos[c] = r.end;
                }
                if stopped {
                    // the list needs a rebuild before the next group
                    break;
                }
            }
            for &c in &live {
                for &i in queues[c] {
                    marks.cell[i] = NONE;
                }
            }
        }
    }
    count
}

/// Mark the particles still to move in the live cells.
fn mark(marks: &mut Marks, queues: &[&[usize]], live: &[usize], pos: &[usize]) {
    for &c in live {
        for (q, &i) in queues[c].iter().enumerate().skip(pos[c]) {
            marks.cell[i] = c as u32;
            marks.slot[i] = q as u32;
        }
    }
}

/// The live cells as groups that can run at once: all of them when no listed pair joins two
/// particles still to move in different cells, else one cell per group.
fn groups(
    list: &NeighbourList,
    marks: &Marks,
    queues: &[&[usize]],
    live: &[usize],
    pos: &[usize],
) -> Vec<Vec<usize>> {
    let joined = live.iter().any(|&c| {
        queues[c][pos[c]..].iter().any(|&i| {
            list.of(i).iter().any(|nb| {
                let o = marks.cell[nb.j as usize];
                o != NONE && o != c as u32
            })
        })
    });
    if joined || live.len() == 1 {
        live.iter().map(|&c| vec![c]).collect()
    } else {
        vec![live.to_vec()]
    }
}

/// The moves of cell `c` from queue position `start`, against `state` with the cell's own
/// moves laid over it; stops after the move that takes a particle past the list's skin.
#[allow(clippy::too_many_arguments)]
fn run_cell(
    state: &PackingState,
    list: &NeighbourList,
    tracker: &OverlapTracker,
    queue: &[usize],
    start: usize,
    c: u32,
    marks: &Marks,
    rule: MoveRule,
    tol: f64,
) -> CellRun {
    // the poses and travels of the cell's moves so far
    let mut poses: Vec<Option<((DVec3, DQuat), f64)>> = vec![None; queue.len() - start];
    let mut moves = Vec::with_capacity(queue.len() - start);
    let mut scratch = Vec::new();
    // the rules that run here draw no random numbers: this stream is never read
    let mut no_rng = unused_rng();
    for (q, &i) in queue.iter().enumerate().skip(start) {
        let mut p = Proposal::default();
        let moved = |j: usize| {
            if marks.cell[j] == c {
                poses[marks.slot[j] as usize - start]
            } else {
                None
            }
        };
        contacts_with(
            state,
            list,
            Some(tracker),
            i,
            tol,
            &mut scratch,
            &mut p.warm,
            moved,
        );
        let (x, o) = (state.positions[i], state.orientations[i]);
        let body = &state.bodies[i];
        p.set_displacement(
            body,
            o,
            overlap_removal_move(rule, body, o, &scratch, &mut no_rng),
        );
        let past_skin = p.displacement.is_some_and(|d| {
            poses[q - start] = Some(((x + d.dx, p.orientation), p.travel));
            list.exceeds_skin(list.moved_of(i) + p.travel)
        });
        moves.push((i, p));
        if past_skin {
            return CellRun { moves, end: q + 1 };
        }
    }
    CellRun {
        moves,
        end: queue.len(),
    }
}

#[cfg(test)]
mod tests;
