//! A configuration: which module is in which cell, and the latch graph it
//! induces on a lattice.

use super::{Cell, Lattice};
use rustc_hash::{FxHashMap, FxHashSet};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Module identifier, as written in schedule files.
pub type ModuleId = u32;

/// The ground: a horizontal plane below layer `layer`. Modules in that layer
/// rest on (and latch to) the ground; cells below it are solid ground.
#[derive(Copy, Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Ground {
    pub layer: i32,
}

impl Ground {
    pub fn is_ground_cell(&self, lattice: &dyn Lattice, c: Cell) -> bool {
        lattice.layer(c) < self.layer
    }

    pub fn touches(&self, lattice: &dyn Lattice, c: Cell) -> bool {
        lattice.layer(c) == self.layer
    }
}

/// Occupancy of lattice cells by modules, indexed both ways.
#[derive(Clone, Debug, Default)]
pub struct Configuration {
    by_cell: FxHashMap<Cell, ModuleId>,
    by_module: FxHashMap<ModuleId, Cell>,
}

impl Configuration {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn len(&self) -> usize {
        self.by_module.len()
    }

    pub fn is_empty(&self) -> bool {
        self.by_module.is_empty()
    }

    /// Places `id` in `cell`. Returns the module already there, if any
    /// (the configuration is left unchanged in that case).
    pub fn insert(&mut self, id: ModuleId, cell: Cell) -> Result<(), ModuleId> {
        if let Some(&other) = self.by_cell.get(&cell) {
            return Err(other);
        }
        if let Some(old) = self.by_module.insert(id, cell) {
            self.by_cell.remove(&old);
        }
        self.by_cell.insert(cell, id);
        Ok(())
    }

    pub fn remove(&mut self, id: ModuleId) -> Option<Cell> {
        let c = self.by_module.remove(&id)?;
        self.by_cell.remove(&c);
        Some(c)
    }

    pub fn at(&self, cell: Cell) -> Option<ModuleId> {
        self.by_cell.get(&cell).copied()
    }

    pub fn cell_of(&self, id: ModuleId) -> Option<Cell> {
        self.by_module.get(&id).copied()
    }

    pub fn contains(&self, id: ModuleId) -> bool {
        self.by_module.contains_key(&id)
    }

    pub fn is_free(&self, cell: Cell) -> bool {
        !self.by_cell.contains_key(&cell)
    }

    /// Modules and their cells, in ascending id order (deterministic).
    pub fn modules(&self) -> Vec<(ModuleId, Cell)> {
        let mut v: Vec<_> = self.by_module.iter().map(|(&m, &c)| (m, c)).collect();
        v.sort_unstable();
        v
    }

    pub fn iter(&self) -> impl Iterator<Item = (ModuleId, Cell)> + '_ {
        self.by_module.iter().map(|(&m, &c)| (m, c))
    }

    /// The modules of the configuration that are not connected, through
    /// latched neighbours, to an anchor (a module touching the ground or a
    /// fixed module). Modules in `exclude` are ignored (they are moving).
    /// In a scene with neither ground nor fixed modules the structure must
    /// form one component: everything outside the component of the lowest
    /// id is returned.
    pub fn unanchored(
        &self,
        lattice: &dyn Lattice,
        ground: Option<Ground>,
        fixed: &FxHashSet<ModuleId>,
        exclude: &FxHashSet<ModuleId>,
        latched: &dyn Fn(ModuleId, ModuleId) -> bool,
    ) -> Vec<ModuleId> {
        let mut seen: FxHashSet<ModuleId> = FxHashSet::default();
        let mut stack: Vec<(ModuleId, Cell)> = Vec::new();
        for (m, c) in self.iter() {
            if exclude.contains(&m) {
                continue;
            }
            let anchored = fixed.contains(&m) || ground.is_some_and(|g| g.touches(lattice, c));
            if anchored && seen.insert(m) {
                stack.push((m, c));
            }
        }
        if ground.is_none()
            && fixed.is_empty()
            && let Some((m, c)) = self
                .modules()
                .into_iter()
                .find(|(m, _)| !exclude.contains(m))
        {
            seen.insert(m);
            stack.push((m, c));
        }
        while let Some((m, c)) = stack.pop() {
            for (o, n) in self.latched_neighbours(lattice, m, c, exclude, latched) {
                if seen.insert(o) {
                    stack.push((o, n));
                }
            }
        }
        let mut out: Vec<ModuleId> = self
            .iter()
            .map(|(m, _)| m)
            .filter(|m| !exclude.contains(m) && !seen.contains(m))
            .collect();
        out.sort_unstable();
        out
    }
}

impl Configuration {
    /// The neighbours of module `m` (at `c`) that are present, not in
    /// `exclude`, and latched to it, with their cells: the edges both
    /// connectivity searches walk.
    fn latched_neighbours<'a>(
        &'a self,
        lattice: &dyn Lattice,
        m: ModuleId,
        c: Cell,
        exclude: &'a FxHashSet<ModuleId>,
        latched: &'a dyn Fn(ModuleId, ModuleId) -> bool,
    ) -> impl Iterator<Item = (ModuleId, Cell)> + 'a {
        lattice
            .neighbours(c)
            .into_iter()
            .filter_map(move |n| self.at(n).map(|o| (o, n)))
            .filter(move |&(o, _)| !exclude.contains(&o) && latched(m, o))
    }

    /// Like [`Configuration::unanchored`], but assuming every module is
    /// anchored before `exclude` is lifted (the configuration was connected),
    /// so only the static neighbours of the lifted modules can have lost
    /// their anchor: a component of the remainder that holds no anchor was
    /// joined to one only through a lifted module, so it contains one of
    /// their neighbours. Searches stop at the first anchor found, which keeps
    /// the cost local to the movers in a well-connected structure. They are
    /// best-first, lowest layer first: the ground is below, so in a solid
    /// structure a search walks down to it in about as many steps as the
    /// mover is high, where a breadth-first search would visit the whole
    /// ball of that radius. (The order changes only the cost: a failed
    /// search still exhausts its component.)
    pub fn unanchored_near(
        &self,
        lattice: &dyn Lattice,
        ground: Option<Ground>,
        fixed: &FxHashSet<ModuleId>,
        exclude: &FxHashSet<ModuleId>,
        latched: &dyn Fn(ModuleId, ModuleId) -> bool,
    ) -> Vec<ModuleId> {
        let is_anchor = |m: ModuleId, c: Cell| {
            fixed.contains(&m) || ground.is_some_and(|g| g.touches(lattice, c))
        };
        let mut anchored: FxHashSet<ModuleId> = FxHashSet::default();
        let mut loose: FxHashSet<ModuleId> = FxHashSet::default();
        let mut seeds: Vec<(ModuleId, Cell)> = Vec::new();
        for &x in exclude {
            let Some(cx) = self.cell_of(x) else { continue };
            seeds.extend(self.latched_neighbours(lattice, x, cx, exclude, latched));
        }
        seeds.sort_unstable();
        seeds.dedup();
        for (seed, seed_cell) in seeds {
            if anchored.contains(&seed) || loose.contains(&seed) {
                continue;
            }
            let mut visited: Vec<ModuleId> = vec![seed];
            let mut seen: FxHashSet<ModuleId> = [seed].into_iter().collect();
            let key = |m: ModuleId, c: Cell| Reverse((lattice.layer(c), m, c));
            let mut queue = BinaryHeap::from([key(seed, seed_cell)]);
            let mut found = false;
            while let Some(Reverse((_, m, c))) = queue.pop() {
                if is_anchor(m, c) || anchored.contains(&m) {
                    found = true;
                    break;
                }
                for (o, n) in self.latched_neighbours(lattice, m, c, exclude, latched) {
                    if seen.insert(o) {
                        visited.push(o);
                        queue.push(key(o, n));
                    }
                }
            }
            // A failed search exhausted its whole component: all of it is loose.
            let target = if found { &mut anchored } else { &mut loose };
            target.extend(visited);
        }
        let mut out: Vec<ModuleId> = loose.into_iter().collect();
        out.sort_unstable();
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::SquareLattice;

    #[test]
    fn two_modules_cannot_share_a_cell() {
        let mut c = Configuration::new();
        c.insert(1, Cell::xy(0, 0)).unwrap();
        assert_eq!(c.insert(2, Cell::xy(0, 0)), Err(1));
        assert_eq!(c.len(), 1);
    }

    #[test]
    fn a_floating_module_is_unanchored() {
        let l = SquareLattice;
        let mut c = Configuration::new();
        c.insert(1, Cell::xy(0, 1)).unwrap();
        c.insert(2, Cell::xy(0, 2)).unwrap();
        c.insert(3, Cell::xy(3, 3)).unwrap();
        let none = FxHashSet::default();
        let g = Some(Ground { layer: 1 });
        assert_eq!(c.unanchored(&l, g, &none, &none, &|_, _| true), vec![3]);
        // Removing the middle of a column disconnects its top.
        let ex: FxHashSet<_> = [1].into_iter().collect();
        assert_eq!(c.unanchored(&l, g, &none, &ex, &|_, _| true), vec![2, 3]);
    }

    #[test]
    fn the_local_search_agrees_with_the_full_one_on_a_connected_start() {
        use rand::{Rng, SeedableRng};
        let l = SquareLattice;
        let g = Some(Ground { layer: 1 });
        let none = FxHashSet::default();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for _ in 0..200 {
            // A random anchored blob grown from the ground.
            let mut c = Configuration::new();
            let mut id = 0;
            c.insert(id, Cell::xy(0, 1)).unwrap();
            while c.len() < 25 {
                let (_, base) = c.modules()[rng.random_range(0..c.len())];
                let n = l.neighbours(base)[rng.random_range(0..4)];
                if n.y >= 1 && c.is_free(n) {
                    id += 1;
                    c.insert(id, n).unwrap();
                }
            }
            assert!(c.unanchored(&l, g, &none, &none, &|_, _| true).is_empty());
            let lifted: FxHashSet<ModuleId> = (0..3).map(|_| rng.random_range(0..=id)).collect();
            let full = c.unanchored(&l, g, &none, &lifted, &|_, _| true);
            let near = c.unanchored_near(&l, g, &none, &lifted, &|_, _| true);
            assert_eq!(full, near);
        }
    }
}
