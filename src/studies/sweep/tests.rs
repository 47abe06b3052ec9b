//! Unit tests of sweep files: value generators, crossing and zipping, seeds, shards.

use std::path::PathBuf;

use super::file::{Sweep, value_cell};
use super::run::{parse_shard, shard_points};

const SCENE: &str = "[simulation]\npipeline = \"packing\"\nseed = 7\n";

fn sweep(text: &str) -> Sweep {
    Sweep::from_texts(text, PathBuf::from("s.toml"), SCENE.into()).unwrap_or_else(|e| panic!("{e}"))
}

fn cells(s: &Sweep, axis: usize) -> Vec<String> {
    s.axes[axis].values.iter().map(value_cell).collect()
}

#[test]
fn generators_give_the_documented_values() {
    let s = sweep(
        "scene = \"x\"\n[[axes]]\npath = \"a\"\nrange = { start = 1, stop = 7, step = 3 }\n\
         [[axes]]\npath = \"b\"\nrange = { start = 0.0, stop = 0.3, step = 0.1 }\n\
         [[axes]]\npath = \"c\"\nlinspace = { start = 0.0, stop = 1.0, num = 5 }\n\
         [[axes]]\npath = \"d\"\nlogspace = { start = 1e-9, stop = 1e-6, num = 4 }\n\
         [[axes]]\npath = \"e\"\nvalues = [\"fire\", 2, [1, 2]]\n",
    );
    // integer ranges stay integers; the stop is included when on the grid
    assert_eq!(cells(&s, 0), ["1", "4", "7"]);
    assert_eq!(s.axes[1].values.len(), 4);
    assert_eq!(cells(&s, 2), ["0.0", "0.25", "0.5", "0.75", "1.0"]);
    let d: Vec<f64> = s.axes[3]
        .values
        .iter()
        .map(|v| v.as_float().unwrap())
        .collect();
    assert_eq!((d[0], d[3]), (1e-9, 1e-6));
    for (k, x) in d.iter().enumerate() {
        assert!((x.log10() - (-9.0 + k as f64)).abs() < 1e-12, "{x}");
    }
    assert!(s.axes[3].log && !s.axes[2].log);
    assert_eq!(cells(&s, 4), ["fire", "2", "[1, 2]"]);
    assert_eq!(s.len(), 3 * 4 * 5 * 4 * 3);
}

#[test]
fn points_cross_axes_first_slowest_with_replicates_innermost() {
    let s = sweep(
        "scene = \"x\"\nreplicates = 2\nseed = 10\nzip = [[\"b\", \"c\"]]\n\
         [[axes]]\npath = \"a\"\nvalues = [1, 2, 3]\n\
         [[axes]]\npath = \"b\"\nvalues = [10, 20]\n\
         [[axes]]\npath = \"c\"\nvalues = [100, 200]\n",
    );
    assert_eq!(s.len(), 3 * 2 * 2);
    let p = s.point(0);
    assert_eq!(
        (p.values.clone(), p.replicate, p.seed),
        (vec![0, 0, 0], 0, Some(10))
    );
    let p = s.point(1);
    assert_eq!(
        (p.values.clone(), p.replicate, p.seed),
        (vec![0, 0, 0], 1, Some(11))
    );
    let p = s.point(3);
    assert_eq!((p.values.clone(), p.replicate), (vec![0, 1, 1], 1));
    let p = s.point(11);
    assert_eq!((p.values.clone(), p.replicate), (vec![2, 1, 1], 1));
    let ovs: Vec<String> = s
        .overrides(&s.point(5))
        .iter()
        .map(|o| o.to_string())
        .collect();
    assert_eq!(ovs, ["a=2", "b=10", "c=100", "simulation.seed=11"]);
}

#[test]
fn seeds_are_the_scenes_own_unless_the_sweep_sets_them() {
    let s = sweep("scene = \"x\"\n[[axes]]\npath = \"a\"\nvalues = [1, 2]\n");
    assert_eq!(s.point(1).seed, None);
    assert_eq!(s.seed_of(&s.point(1)), Some(7));
    assert_eq!(s.overrides(&s.point(1)).len(), 1);
    // replicates alone: the base seed is the scene's
    let s = sweep("scene = \"x\"\nreplicates = 3\n[[axes]]\npath = \"a\"\nvalues = [1]\n");
    let seeds: Vec<_> = (0..3).map(|i| s.point(i).seed).collect();
    assert_eq!(seeds, [Some(7), Some(8), Some(9)]);
}

#[test]
fn shards_partition_the_points() {
    assert_eq!(parse_shard("2/3"), Ok((2, 3)));
    for bad in ["0/3", "4/3", "3", "a/b", "1/0"] {
        assert!(parse_shard(bad).is_err(), "{bad}");
    }
    let mut all: Vec<usize> = (1..=3)
        .flat_map(|i| shard_points(10, Some((i, 3))))
        .collect();
    assert_eq!(shard_points(10, Some((1, 3))), [0, 3, 6, 9]);
    all.sort();
    assert_eq!(all, (0..10).collect::<Vec<_>>());
}
