//! Mechanics of seed 004's atoms: the force each arm must exert in a
//! parallel step to drag what it moves across the ground.
//!
//! The 2D robots of the paper lie flat on a table (gravity −z, the robot
//! in the xy-plane), so gravity loads no face in bending; what the faces
//! carry is the friction of the atoms an arm drags or pushes. Within a
//! step, the bonds whose arm changes length split the robot into rigid
//! parts; the part holding the anchor stays (the certifier's frame: the
//! fixed atoms, or a free robot's heaviest rigid part), every other part moves, and a
//! changing bond carries the friction `μ·m·g` of every atom in the parts
//! beyond it (seen from the anchor), shared equally with the bonds in
//! parallel with it between the same two parts. That force pulls the
//! attached faces apart when the arm contracts, and is what the arm pushes
//! with when it expands: both are held to the face strength of the model
//! (the connector's tension capacity `p·L²`, [`crate::mechanics::Capacity::tension`]).

use rustc_hash::FxHashMap;
use std::collections::VecDeque;

/// The load of one changing bond.
#[derive(Clone, Debug, PartialEq)]
pub struct DriveLoad {
    /// Index of the bond in the list given to [`drive_loads`].
    pub bond: usize,
    /// Atoms it moves (the parts beyond it).
    pub atoms: usize,
    /// Force (N).
    pub force: f64,
}

/// The rigid parts of a step: each atom's part, the atoms joined by the
/// held `bonds` whose length does not change (`changing[k]` false), by
/// union–find (petgraph's). Part labels are arbitrary.
pub fn rigid_parts(n: usize, bonds: &[(usize, usize)], changing: &[bool]) -> Vec<usize> {
    let mut parts = petgraph::unionfind::UnionFind::<usize>::new(n);
    for (&(a, b), &c) in bonds.iter().zip(changing) {
        if !c {
            parts.union(a, b);
        }
    }
    parts.into_labeling()
}

/// The drive loads of one step. `bonds`: the attachments held through the
/// step (atom pairs); `changing[k]`: whether bond `k`'s length changes;
/// `anchor`: an atom that stays; `drag`: the friction force of one atom
/// (N). Bonds that do not change are rigid and carry nothing here.
pub fn drive_loads(
    n: usize,
    bonds: &[(usize, usize)],
    changing: &[bool],
    anchor: usize,
    drag: f64,
) -> Vec<DriveLoad> {
    let part = rigid_parts(n, bonds, changing);
    let mut size: FxHashMap<usize, usize> = FxHashMap::default();
    for &p in &part {
        *size.entry(p).or_default() += 1;
    }
    // The graph of parts joined by changing bonds.
    let mut adj: FxHashMap<usize, Vec<(usize, usize)>> = FxHashMap::default();
    for (k, &(a, b)) in bonds.iter().enumerate() {
        if changing[k] && part[a] != part[b] {
            adj.entry(part[a]).or_default().push((part[b], k));
            adj.entry(part[b]).or_default().push((part[a], k));
        }
    }
    // A BFS tree from the anchor's part; each part's parent edge.
    let root = part[anchor];
    let mut order = vec![root];
    let mut up: FxHashMap<usize, usize> = FxHashMap::default();
    let mut seen: FxHashMap<usize, ()> = FxHashMap::default();
    seen.insert(root, ());
    let mut q = VecDeque::from([root]);
    while let Some(u) = q.pop_front() {
        for &(v, _) in adj.get(&u).map(Vec::as_slice).unwrap_or(&[]) {
            if seen.insert(v, ()).is_none() {
                up.insert(v, u);
                order.push(v);
                q.push_back(v);
            }
        }
    }
    // Atoms in each part's subtree, leaves first.
    let mut acc: FxHashMap<usize, usize> = FxHashMap::default();
    let mut beyond: FxHashMap<usize, usize> = FxHashMap::default();
    for &p in order.iter().rev() {
        let here = size[&p] + acc.get(&p).copied().unwrap_or(0);
        beyond.insert(p, here);
        if let Some(&u) = up.get(&p) {
            *acc.entry(u).or_default() += here;
        }
    }
    let mut out = Vec::new();
    for (&child, &parent_part) in &up {
        let carried = beyond[&child];
        let parallel: Vec<usize> = adj[&child]
            .iter()
            .filter(|&&(v, _)| v == parent_part)
            .map(|&(_, k)| k)
            .collect();
        let share = carried as f64 * drag / parallel.len() as f64;
        for k in parallel {
            out.push(DriveLoad {
                bond: k,
                atoms: carried,
                force: share,
            });
        }
    }
    out.sort_by_key(|d| d.bond);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_arm_dragging_a_chain_carries_its_whole_friction() {
        // 0 — 1 ⇢ 2 — 3 — 4: the changing bond (1, 2) drags three atoms.
        let bonds = [(0, 1), (1, 2), (2, 3), (3, 4)];
        let changing = [false, true, false, false];
        let loads = drive_loads(5, &bonds, &changing, 0, 0.5);
        assert_eq!(loads.len(), 1);
        assert_eq!(loads[0].atoms, 3);
        assert!((loads[0].force - 1.5).abs() < 1e-12);
        // Mirror image: anchored at the other end, the arm drags two.
        let loads = drive_loads(5, &bonds, &changing, 4, 0.5);
        assert_eq!(loads[0].atoms, 2);
    }

    #[test]
    fn parallel_arms_share_and_chained_arms_add_up() {
        // 0 ⇢ 1 — 2 ⇢ 3, and 0 ⇢ 2 in parallel with 0 ⇢ 1's part.
        let bonds = [(0, 1), (1, 2), (2, 3), (0, 2)];
        let changing = [true, false, true, true];
        let loads = drive_loads(4, &bonds, &changing, 0, 1.0);
        let by: FxHashMap<usize, f64> = loads.iter().map(|d| (d.bond, d.force)).collect();
        // Part {1, 2} with part {3} beyond it: 3 atoms over 2 parallel arms.
        assert!((by[&0] - 1.5).abs() < 1e-12);
        assert!((by[&3] - 1.5).abs() < 1e-12);
        assert!((by[&2] - 1.0).abs() < 1e-12);
    }
}
