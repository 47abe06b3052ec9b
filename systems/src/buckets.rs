//! Stable counting sort of items into buckets: the layout of the cell lists (the collision
//! grid, the packing sweep's queues by cell), one bucket's items contiguous in one array.

/// Sort the items `0..keys.len()` by bucket `keys[i]` (each < `buckets`), stably: `start`
/// becomes the `buckets + 1` offsets, bucket b holding `items[start[b]..start[b + 1]]`, and
/// `items` the item indices, ascending within a bucket. Both vectors are cleared and
/// refilled (their capacity is reused).
///
/// ```
/// use magsep_systems::buckets::bucket_sort;
/// let (mut start, mut items) = (Vec::new(), Vec::new());
/// bucket_sort(&[2, 0, 2, 1, 0], 4, &mut start, &mut items);
/// assert_eq!(start, vec![0, 2, 3, 5, 5]);
/// assert_eq!(items, vec![1, 4, 3, 0, 2]);
/// ```
pub fn bucket_sort(keys: &[usize], buckets: usize, start: &mut Vec<usize>, items: &mut Vec<u32>) {
    start.clear();
    start.resize(buckets + 1, 0);
    for &b in keys {
        start[b + 1] += 1;
    }
    for b in 0..buckets {
        start[b + 1] += start[b];
    }
    items.clear();
    items.resize(keys.len(), 0);
    let mut fill = start.clone();
    for (i, &b) in keys.iter().enumerate() {
        items[fill[b]] = i as u32;
        fill[b] += 1;
    }
}
