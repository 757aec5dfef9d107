//! Work of an elimination tree split between threads: disjoint subtrees, each a contiguous
//! range of nodes, packed into bins of about equal work.
//!
//! A left-looking factorization computes a node from its own entries and its descendants'
//! results only, so disjoint subtrees can be computed at once, each by one thread, and the
//! nodes above them (the top of the tree, the root separators) after them, in order: every
//! node is computed by the same operations whatever the thread that runs it, and the
//! result is bit for bit the sequential one.
//!
//! The nodes are in topological order (a parent after its children), and mostly in
//! postorder: a subtree whose nodes are not one contiguous range `first..=root` (faer's
//! supernodal amalgamation leaves a few) is always opened. The split: starting from the
//! roots, the subtree of largest work is replaced by its children (its root joins the top)
//! while that lowers the bound `top + max(largest subtree, all subtrees / bins)` on the
//! parallel time, at most [`MAX_EXPANSIONS`] times; the subtrees are then packed largest
//! first into the bin of least work (LPT). O(expansions x frontier + nodes).

/// How many subtree roots the split may move to the top. A tree whose work sits in a long
/// chain of separators (where no split helps) stops there.
pub const MAX_EXPANSIONS: usize = 256;

/// The shape of a forest in topological order: node `s`'s parent `parent[s]` (`None` for
/// a root) is after it; its subtree spans the nodes `first[s]..=s`, all of them where
/// `contiguous[s]`.
#[derive(Clone, Debug, Default)]
pub struct Forest {
    parent: Vec<Option<usize>>,
    first: Vec<usize>,
    contiguous: Vec<bool>,
    /// Children of each node, as ranges into `child_list`.
    child_ptr: Vec<usize>,
    child_list: Vec<usize>,
}

impl Forest {
    /// The forest of `parent`, or `None` when a parent is not after its child.
    pub fn new(parent: Vec<Option<usize>>) -> Option<Self> {
        let n = parent.len();
        let mut first: Vec<usize> = (0..n).collect();
        let mut size = vec![1usize; n];
        for s in 0..n {
            if let Some(p) = parent[s] {
                if p <= s || p >= n {
                    return None;
                }
                first[p] = first[p].min(first[s]);
                size[p] += size[s];
            }
        }
        let contiguous = (0..n).map(|s| s + 1 - first[s] == size[s]).collect();
        let mut child_ptr = vec![0; n + 1];
        for p in parent.iter().flatten() {
            child_ptr[p + 1] += 1;
        }
        for s in 0..n {
            child_ptr[s + 1] += child_ptr[s];
        }
        let mut fill = child_ptr.clone();
        let mut child_list = vec![0; child_ptr[n]];
        for (s, p) in parent.iter().enumerate() {
            if let Some(p) = *p {
                child_list[fill[p]] = s;
                fill[p] += 1;
            }
        }
        Some(Forest {
            parent,
            first,
            contiguous,
            child_ptr,
            child_list,
        })
    }

    fn children(&self, s: usize) -> impl Iterator<Item = usize> + '_ {
        self.child_list[self.child_ptr[s]..self.child_ptr[s + 1]]
            .iter()
            .copied()
    }

    pub fn len(&self) -> usize {
        self.parent.len()
    }

    pub fn is_empty(&self) -> bool {
        self.parent.is_empty()
    }

    /// Subtrees (as node ranges `first..=root`, returned `(first, root)`) in `bins` bins of
    /// about equal total `work` (one entry per node, `>= 0`); nodes in no returned subtree
    /// are the top, to be computed after them. `None` when fewer than two bins would hold
    /// work (nothing to run at once).
    pub fn split(&self, work: &[f64], bins: usize) -> Option<Vec<Vec<(usize, usize)>>> {
        let n = self.len();
        if bins < 2 || work.len() != n {
            return None;
        }
        let mut subtree = work.to_vec();
        for s in 0..n {
            if let Some(p) = self.parent[s] {
                subtree[p] += subtree[s];
            }
        }
        // Adds the subtrees of `nodes` with work to `frontier`, opening the non-contiguous
        // ones (their roots' work to `top`).
        let add = |nodes: Vec<usize>, frontier: &mut Vec<usize>, top: &mut f64| {
            let mut open = nodes;
            while let Some(s) = open.pop() {
                if subtree[s] <= 0.0 {
                    continue;
                }
                if self.contiguous[s] {
                    frontier.push(s);
                } else {
                    *top += work[s];
                    open.extend(self.children(s));
                }
            }
        };
        let mut top = 0.0;
        let mut frontier = Vec::new();
        let roots = (0..n).filter(|&s| self.parent[s].is_none()).collect();
        add(roots, &mut frontier, &mut top);
        frontier.sort_unstable();
        // The parallel time of a frontier, bounded below: the top's work plus the larger of
        // the largest subtree and an even share.
        let cost = |frontier: &[usize], top: f64| {
            let (largest, total) = frontier.iter().fold((0.0f64, 0.0), |(m, t), &s| {
                (m.max(subtree[s]), t + subtree[s])
            });
            top + largest.max(total / bins as f64)
        };
        for _ in 0..MAX_EXPANSIONS {
            let Some((at, &largest)) = frontier
                .iter()
                .enumerate()
                .max_by(|a, b| subtree[*a.1].total_cmp(&subtree[*b.1]).then(b.1.cmp(a.1)))
            else {
                break;
            };
            let mut opened = frontier.clone();
            opened.swap_remove(at);
            let mut opened_top = top + work[largest];
            add(
                self.children(largest).collect(),
                &mut opened,
                &mut opened_top,
            );
            if cost(&opened, opened_top) >= cost(&frontier, top) {
                break;
            }
            frontier = opened;
            top = opened_top;
        }
        // Largest first, ties by node, into the lightest bin (ties: the first).
        frontier.sort_by(|&a, &b| subtree[b].total_cmp(&subtree[a]).then(a.cmp(&b)));
        let mut load = vec![0.0f64; bins];
        let mut out = vec![Vec::new(); bins];
        for s in frontier {
            let bin = (0..bins)
                .min_by(|&a, &b| load[a].total_cmp(&load[b]))
                .expect("bins >= 2");
            load[bin] += subtree[s];
            out[bin].push((self.first[s], s));
        }
        for bin in &mut out {
            bin.sort_unstable();
        }
        (out.iter().filter(|b| !b.is_empty()).count() >= 2).then_some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::Forest;

    /// Two chains of three under a root: 0-1-2 -> 6, 3-4-5 -> 6.
    fn two_chains() -> Forest {
        let parent = vec![Some(1), Some(2), Some(6), Some(4), Some(5), Some(6), None];
        Forest::new(parent).expect("topological")
    }

    #[test]
    fn a_parent_before_its_child_is_refused_and_a_scattered_subtree_is_opened() {
        assert!(Forest::new(vec![Some(2), Some(2), None]).is_some());
        assert!(Forest::new(vec![Some(2), None, Some(1)]).is_none());
        // 3's subtree is {0, 3}; 1 and 2 (its own tree) lie between: 3 is opened, 0 and
        // 1..2 go to the bins, 3 stays on top.
        let forest = Forest::new(vec![Some(3), Some(2), None, None]).expect("topological");
        let bins = forest.split(&[4.0, 2.0, 2.0, 1.0], 2).expect("a split");
        assert_eq!(bins, vec![vec![(0, 0)], vec![(1, 2)]]);
    }

    #[test]
    fn balanced_chains_go_to_two_bins_and_the_root_stays_on_top() {
        let forest = two_chains();
        let work = [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 10.0];
        let bins = forest.split(&work, 2).expect("a split");
        assert_eq!(bins, vec![vec![(0, 2)], vec![(3, 5)]]);
    }

    #[test]
    fn an_unbalanced_subtree_is_opened_and_packed_largest_first() {
        // Chain 0-1-2 heavy at its leaf: the root opened (bound 13 -> 1 + 9), then opening
        // 2 (-> 2 + 8) gains nothing, so 0..2 (9) against 3..5 (3) under the root.
        let forest = two_chains();
        let work = [7.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0];
        let bins = forest.split(&work, 2).expect("a split");
        assert_eq!(bins, vec![vec![(0, 2)], vec![(3, 5)]]);
        // Three equal chains under a root, three bins: one each.
        let three = Forest::new(vec![
            Some(1),
            Some(6),
            Some(3),
            Some(6),
            Some(5),
            Some(6),
            None,
        ])
        .expect("topological");
        let even = [2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 1.0];
        let bins = three.split(&even, 3).expect("a split");
        assert_eq!(bins, vec![vec![(0, 1)], vec![(2, 3)], vec![(4, 5)]]);
        // Work only on one side: nothing to run at once.
        let one_sided = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        assert!(forest.split(&one_sided, 2).is_none());
    }

    #[test]
    fn every_node_with_work_is_in_one_subtree_or_on_top_and_bins_are_disjoint() {
        // A random postordered forest: each node's parent a later node, built by a
        // postorder walk of a random tree.
        let mut seed = 12345u64;
        let mut rand = |m: usize| {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
            ((seed >> 33) as usize) % m
        };
        // Random tree over 200 nodes by parent links, then renumbered in postorder.
        let n = 200;
        let tree_parent: Vec<Option<usize>> = (0..n)
            .map(|i| if i == 0 { None } else { Some(rand(i)) })
            .collect();
        let mut children = vec![Vec::new(); n];
        for (i, p) in tree_parent.iter().enumerate() {
            if let Some(p) = p {
                children[*p].push(i);
            }
        }
        let mut order = Vec::new();
        fn post(v: usize, children: &[Vec<usize>], order: &mut Vec<usize>) {
            for &c in &children[v] {
                post(c, children, order);
            }
            order.push(v);
        }
        post(0, &children, &mut order);
        let mut new_of = vec![0; n];
        for (new, &old) in order.iter().enumerate() {
            new_of[old] = new;
        }
        let mut parent = vec![None; n];
        for old in 0..n {
            parent[new_of[old]] = tree_parent[old].map(|p| new_of[p]);
        }
        let forest = Forest::new(parent.clone()).expect("topological");
        let work: Vec<f64> = (0..n).map(|_| rand(100) as f64).collect();
        for bins in [2, 3, 5] {
            let split = forest.split(&work, bins).expect("a split");
            let mut owner = vec![None; n];
            for (b, ranges) in split.iter().enumerate() {
                for &(first, root) in ranges {
                    for s in first..=root {
                        assert!(owner[s].is_none(), "node {s} in two subtrees");
                        owner[s] = Some(b);
                    }
                }
            }
            // A node on top is never below a node in a subtree (its descendants are
            // computed first), and a subtree's nodes' parents are in it or on top.
            for s in 0..n {
                if owner[s].is_none() {
                    let mut p = parent[s];
                    while let Some(q) = p {
                        assert!(owner[q].is_none(), "top node {s} under subtree node {q}");
                        p = parent[q];
                    }
                }
            }
            let loads: Vec<f64> = split
                .iter()
                .map(|r| {
                    r.iter()
                        .map(|&(f, l)| work[f..=l].iter().sum::<f64>())
                        .sum()
                })
                .collect();
            println!("bins {bins}: loads {loads:?}");
            assert!(loads.iter().filter(|&&l| l > 0.0).count() >= 2);
        }
    }
}
