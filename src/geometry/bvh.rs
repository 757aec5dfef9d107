//! Bounding-volume hierarchy over axis-aligned boxes, with nearest-first traversal.
//!
//! Built top-down: a node's items are split at the median of their box centres along the
//! longest axis of the centres' spread, down to one item per leaf (so a tree of `n` items
//! has `2n - 1` nodes and depth `ceil(log2 n)`). A query visits items in non-decreasing
//! order of the distance from the point to their box (best-first search with a binary
//! heap keyed on box distance, which is a lower bound of every descendant's), and stops
//! as soon as the nearest unvisited box is farther than the caller's current bound. This
//! is the order of a full sort of the boxes by distance, at `O(log n)` cost per visited
//! item when the bound prunes early.

use super::Vec3;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

#[derive(Clone, Debug)]
struct Node {
    lo: Vec3,
    hi: Vec3,
    /// Children, or the item of a leaf.
    content: Content,
}

#[derive(Clone, Copy, Debug)]
enum Content {
    Inner(usize, usize),
    Leaf(usize),
}

/// An AABB tree over items given by their boxes.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<Node>,
}

/// Distance from `x` to the box `[lo, hi]` (0 inside).
pub fn box_distance(lo: &Vec3, hi: &Vec3, x: &Vec3) -> f64 {
    let below = (lo - x).sup(&Vec3::zeros());
    let above = (x - hi).sup(&Vec3::zeros());
    (below + above).norm()
}

/// Heap entry: smallest distance first (BinaryHeap is a max-heap), ties by node index so
/// that the order is deterministic.
#[derive(PartialEq)]
struct Entry(f64, usize);

impl Eq for Entry {}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        other.0.total_cmp(&self.0).then(other.1.cmp(&self.1))
    }
}

impl Bvh {
    /// Tree over `boxes[i] = (lo, hi)`; empty for no boxes.
    pub fn new(boxes: &[(Vec3, Vec3)]) -> Bvh {
        let mut bvh = Bvh { nodes: Vec::new() };
        if !boxes.is_empty() {
            let mut items: Vec<usize> = (0..boxes.len()).collect();
            bvh.build(boxes, &mut items);
        }
        bvh
    }

    /// Builds the subtree over `items` and returns its node index.
    fn build(&mut self, boxes: &[(Vec3, Vec3)], items: &mut [usize]) -> usize {
        let (lo, hi) = items.iter().fold(
            (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
            |(lo, hi), &i| (lo.inf(&boxes[i].0), hi.sup(&boxes[i].1)),
        );
        let index = self.nodes.len();
        self.nodes.push(Node {
            lo,
            hi,
            content: Content::Leaf(items[0]),
        });
        if items.len() > 1 {
            let centre = |i: usize| (boxes[i].0 + boxes[i].1) * 0.5;
            let (clo, chi) = items.iter().fold(
                (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
                |(lo, hi), &i| (lo.inf(&centre(i)), hi.sup(&centre(i))),
            );
            let axis = (chi - clo).imax();
            let mid = items.len() / 2;
            items.select_nth_unstable_by(mid, |&a, &b| centre(a)[axis].total_cmp(&centre(b)[axis]));
            let (left_items, right_items) = items.split_at_mut(mid);
            let left = self.build(boxes, left_items);
            let right = self.build(boxes, right_items);
            self.nodes[index].content = Content::Inner(left, right);
        }
        index
    }

    /// Visits items in non-decreasing order of box distance to `x`: `visit(item, distance)`
    /// returns the current bound (initially `bound`), and the traversal stops at the first
    /// box farther than it.
    pub fn nearest_first(
        &self,
        x: &Vec3,
        mut bound: f64,
        mut visit: impl FnMut(usize, f64) -> f64,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let mut heap = BinaryHeap::new();
        let root = &self.nodes[0];
        heap.push(Entry(box_distance(&root.lo, &root.hi, x), 0));
        while let Some(Entry(d, k)) = heap.pop() {
            if d > bound {
                break;
            }
            match self.nodes[k].content {
                Content::Leaf(item) => bound = visit(item, d),
                Content::Inner(a, b) => {
                    for c in [a, b] {
                        let n = &self.nodes[c];
                        heap.push(Entry(box_distance(&n.lo, &n.hi, x), c));
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::testutil::Rng;

    /// Traversal order equals the sorted order of box distances, and the bound prunes
    /// exactly the boxes beyond it.
    #[test]
    fn nearest_first_is_the_sorted_order() {
        let mut rng = Rng::new(7);
        let boxes: Vec<(Vec3, Vec3)> = (0..300)
            .map(|_| {
                let lo = rng.vec3(10.0);
                (
                    lo,
                    lo + Vec3::new(rng.uniform(0.0, 2.0), rng.uniform(0.0, 2.0), 0.5),
                )
            })
            .collect();
        let bvh = Bvh::new(&boxes);
        for _ in 0..200 {
            let x = rng.vec3(12.0);
            let mut sorted: Vec<f64> = boxes.iter().map(|(l, h)| box_distance(l, h, &x)).collect();
            sorted.sort_by(f64::total_cmp);
            let mut seen = Vec::new();
            bvh.nearest_first(&x, f64::INFINITY, |_, d| {
                seen.push(d);
                f64::INFINITY
            });
            assert_eq!(seen, sorted);
            let cut = sorted[20];
            let mut pruned = Vec::new();
            bvh.nearest_first(&x, f64::INFINITY, |_, d| {
                pruned.push(d);
                cut
            });
            assert_eq!(pruned.len(), sorted.iter().filter(|&&d| d <= cut).count());
        }
        let mut none = 0;
        Bvh::new(&[]).nearest_first(&Vec3::zeros(), f64::INFINITY, |_, _| {
            none += 1;
            0.0
        });
        assert_eq!(none, 0);
    }
}
