//! Certification of seed 004's atom schedules (cubic lattice, `atoms` set):
//! every parallel step of expand / contract / attach / detach operations is
//! replayed and checked for
//!
//! * **arm kinematics** — the attached faces held through the step and the
//!   arms at its end fix every atom's end position
//!   ([`crate::geometry::atom::solve_step`]); arms that disagree around a
//!   cycle are an `arm_conflict` (the state is then undefined: replay stops);
//! * **collision** — bodies and arms, as they move, never interpenetrate by
//!   more than ε (exact moving-box test, [`crate::geometry::atom::first_overlap`]);
//! * **connectivity** — the attached-face graph held through the step is
//!   connected;
//! * **in place** — every body and arm, over its whole sweep, stays inside
//!   the union of the source's and the target's bounding boxes;
//! * **mechanics**, where a model is given — each changing arm's drive load
//!   ([`crate::mechanics::atom`]) within the face strength.
//!
//! Detaches take effect at the start of the step, attaches at its end (the
//! faces must then touch). The world frame is held by the `fixed` atoms, or
//! else by the first atom listed.

use super::report::{REPORT_FORMAT, Report, StepResult, Violation, ViolationKind};
use super::{Options, model_path};
use crate::error::InputError;
use crate::geometry::atom::{
    Bond, Faces, MovingBox, atom_boxes, contact_face, first_overlap, solve_step, sweep_hull,
    within_union,
};
use crate::lattice::config::ModuleId;
use crate::lattice::{AtomRest, Cell, Face};
use crate::schedule::{Event, Schedule, Step};
use rustc_hash::{FxHashMap, FxHashSet};
use std::collections::BTreeSet;

/// The names of the checks, as listed in the report.
pub const CHECKS: [&str; 4] = [
    "atoms: events and arm kinematics",
    "atoms: collision (exact moving boxes)",
    "atoms: attached-face connectivity",
    "atoms: in place (union of source and target bounding boxes)",
];
/// The mechanics check's name in the report.
pub const MECHANICS: &str = "atoms: mechanics (arm drive loads vs face strength)";

/// The state of every atom between steps.
#[derive(Clone, Debug)]
pub struct AtomState {
    pub ids: Vec<ModuleId>,
    pub pos: Vec<Cell>,
    pub ext: Vec<Faces>,
    /// Attached pairs `(a, b)`, `a < b`, by index.
    pub bonds: BTreeSet<(usize, usize)>,
    pub anchors: Vec<usize>,
    /// No atom is fixed: the robot lies free (on a table), and in each
    /// step the frame is its heaviest part ([`AtomState::advance`]).
    pub floating: bool,
    index: FxHashMap<ModuleId, usize>,
}

/// One step's events, resolved.
#[derive(Clone, Debug, Default)]
pub struct AtomPlan {
    pub ext1: Vec<Faces>,
    pub toggled: FxHashSet<(usize, Face)>,
    pub attach: Vec<(usize, usize)>,
    pub detach: Vec<(usize, usize)>,
    pub operations: usize,
}

/// What one step did: the positions at its end and what was found.
#[derive(Clone, Debug, Default)]
pub struct StepFindings {
    pub violations: Vec<Violation>,
    pub max_utilisation: Option<f64>,
    /// Set when the end of the step is undefined (an arm conflict).
    pub stop: bool,
}

fn pair(a: usize, b: usize) -> (usize, usize) {
    if a < b { (a, b) } else { (b, a) }
}

impl AtomState {
    /// The initial configuration: every face in the rest state, every
    /// touching pair of faces attached.
    pub fn initial(s: &Schedule, rest: AtomRest) -> Result<AtomState, InputError> {
        let faces = [rest == AtomRest::Expanded; 6];
        let mut index = FxHashMap::default();
        let mut by_cell: FxHashMap<Cell, usize> = FxHashMap::default();
        for (k, m) in s.modules.iter().enumerate() {
            if index.insert(m.id, k).is_some() {
                return Err(
                    InputError::new(format!("atom id {} is used twice", m.id)).for_module(m.id)
                );
            }
            if let Some(o) = by_cell.insert(m.cell, k) {
                return Err(InputError::new(format!(
                    "atoms {} and {} are both at {}",
                    s.modules[o].id, m.id, m.cell
                ))
                .for_module(m.id));
            }
        }
        let pos: Vec<Cell> = s.modules.iter().map(|m| m.cell).collect();
        let ext = vec![faces; pos.len()];
        let mut bonds = BTreeSet::new();
        for (a, &p) in pos.iter().enumerate() {
            for f in [Face::PosX, Face::PosY, Face::PosZ] {
                let q = p + crate::geometry::atom::bond_offset(f, &faces, &faces);
                if let Some(&b) = by_cell.get(&q) {
                    bonds.insert(pair(a, b));
                }
            }
        }
        let mut anchors: Vec<usize> = (0..pos.len()).filter(|&k| s.modules[k].fixed).collect();
        let floating = anchors.is_empty();
        if floating && !pos.is_empty() {
            anchors.push(0);
        }
        Ok(AtomState {
            ids: s.modules.iter().map(|m| m.id).collect(),
            pos,
            ext,
            bonds,
            anchors,
            floating,
            index,
        })
    }

    fn atom(&self, id: ModuleId, step: usize) -> Result<usize, InputError> {
        self.index.get(&id).copied().ok_or_else(|| {
            InputError::new(format!("atom {id} is not in the robot"))
                .at_step(step)
                .for_module(id)
        })
    }

    /// Resolves step `k` (1-based): unknown atoms, faces expanded twice or
    /// contracted twice, two operations on one face in one step, and events
    /// that are not atom operations are unusable input.
    pub fn plan(&self, k: usize, step: &Step) -> Result<AtomPlan, InputError> {
        let mut plan = AtomPlan {
            ext1: self.ext.clone(),
            ..Default::default()
        };
        for e in &step.events {
            let id = e.module();
            let a = self.atom(id, k)?;
            let err = |m: String| InputError::new(m).at_step(k).for_module(id);
            match e {
                Event::Expand { face, .. } | Event::Contract { face, .. } => {
                    let expand = matches!(e, Event::Expand { .. });
                    if !plan.toggled.insert((a, *face)) {
                        return Err(err(format!(
                            "face {} of atom {id} is given two operations in one step",
                            face.name()
                        )));
                    }
                    let now = self.ext[a][face.index()];
                    if now == expand {
                        return Err(err(format!(
                            "face {} of atom {id} is already {}",
                            face.name(),
                            if now { "expanded" } else { "contracted" }
                        )));
                    }
                    plan.ext1[a][face.index()] = expand;
                }
                Event::Attach { other, .. } | Event::Detach { other, .. } => {
                    let b = self.atom(*other, k)?;
                    if a == b {
                        return Err(err(format!("atom {id} cannot latch to itself")));
                    }
                    if matches!(e, Event::Attach { .. }) {
                        plan.attach.push(pair(a, b));
                    } else {
                        plan.detach.push(pair(a, b));
                    }
                }
                _ => {
                    return Err(err(
                        "only expand, contract, attach and detach act on atoms".to_string()
                    ));
                }
            }
            plan.operations += 1;
        }
        Ok(plan)
    }

    /// The bonds held through a step: the current ones less the detached.
    fn held(&self, plan: &AtomPlan) -> Vec<(usize, usize)> {
        let gone: FxHashSet<(usize, usize)> = plan.detach.iter().copied().collect();
        self.bonds
            .iter()
            .copied()
            .filter(|p| !gone.contains(p))
            .collect()
    }

    fn bond_of(&self, (a, b): (usize, usize)) -> Bond {
        let face = contact_face(self.pos[a], &self.ext[a], self.pos[b], &self.ext[b])
            .expect("attached atoms touch");
        Bond { a, face, b }
    }

    /// Runs step `k` (1-based): the end positions, then the state after it.
    /// `checks` carries what the checks need; without it only the
    /// kinematics runs (to find the target).
    pub fn advance(&mut self, k: usize, plan: AtomPlan, checks: Option<&Checks>) -> StepFindings {
        let mut out = StepFindings::default();
        for &(a, b) in &plan.detach {
            if !self.bonds.contains(&(a, b)) {
                out.violations.push(
                    Violation::new(
                        ViolationKind::LatchNotAdjacent,
                        k,
                        format!(
                            "detach of atoms {} and {}, which are not attached",
                            self.ids[a], self.ids[b]
                        ),
                    )
                    .modules([self.ids[a], self.ids[b]]),
                );
            }
        }
        let held = self.held(&plan);
        let bonds: Vec<Bond> = held.iter().map(|&p| self.bond_of(p)).collect();
        // Which held bonds change length: the frame of a free robot and
        // the drive loads both split the robot into rigid parts by them
        // (neither needed: not computed).
        let changing: Vec<bool> = if self.floating || checks.is_some_and(|c| c.mechanics.is_some())
        {
            bonds
                .iter()
                .map(|b| {
                    plan.toggled.contains(&(b.a, b.face))
                        || plan.toggled.contains(&(b.b, b.face.opposite()))
                })
                .collect()
        } else {
            Vec::new()
        };
        let end = match solve_step(&self.pos, &plan.ext1, &bonds, &self.anchors) {
            Ok(end) if self.floating => self.hold_heaviest(end, &held, &changing),
            Ok(end) => end,
            Err(c) => {
                out.violations.push(
                    Violation::new(
                        ViolationKind::ArmConflict,
                        k,
                        format!(
                            "the arms changing in this step disagree around a cycle of attached faces: atom {} would be at {} and at {}",
                            self.ids[c.atoms.1], c.expected, c.found
                        ),
                    )
                    .modules([self.ids[c.atoms.0], self.ids[c.atoms.1]])
                    .cells([c.expected, c.found]),
                );
                out.stop = true;
                return out;
            }
        };
        let active: Vec<usize> = (0..self.pos.len())
            .filter(|&a| end[a] != self.pos[a] || plan.ext1[a] != self.ext[a])
            .collect();
        if let Some(ch) = checks {
            self.connectivity(k, &held, &mut out);
            self.collisions(k, &end, &plan, &active, ch.epsilon, &mut out);
            self.in_place(k, &end, &plan, &active, ch, &mut out);
            if let Some(m) = &ch.mechanics {
                self.mechanics(k, &held, &changing, m, &mut out);
            }
        }
        // Attaches at the end of the step: the faces must touch then.
        let mut bonds: BTreeSet<(usize, usize)> = held.into_iter().collect();
        for &(a, b) in &plan.attach {
            if contact_face(end[a], &plan.ext1[a], end[b], &plan.ext1[b]).is_some() {
                bonds.insert((a, b));
            } else {
                out.violations.push(
                    Violation::new(
                        ViolationKind::LatchNotAdjacent,
                        k,
                        format!(
                            "attach of atoms {} and {}, whose faces do not touch at the end of the step",
                            self.ids[a], self.ids[b]
                        ),
                    )
                    .modules([self.ids[a], self.ids[b]])
                    .cells([end[a], end[b]]),
                );
            }
        }
        // A held bond whose faces no longer touch cannot happen: the solve
        // keeps every held bond's offset; the ones the solve could not
        // reach belong to a disconnected part, reported above.
        self.pos = end;
        self.ext = plan.ext1;
        self.bonds = bonds;
        out
    }

    /// A robot with no fixed atom, in a step solved from an arbitrary
    /// anchor: the step's motion seen from its heaviest rigid part (the
    /// most atoms joined by bonds whose length does not change; ties: the
    /// part of the lowest-numbered atom), which becomes the anchor. On a
    /// table the heaviest part holds by its friction and the others slide,
    /// as [`crate::mechanics::atom`] has it. From atom 0 instead, a step
    /// that carries atom 0 along would move everything else, out of the
    /// bounding boxes, and drag it all: seed 004's combing in 3D moves
    /// every meta-module at some step.
    fn hold_heaviest(
        &mut self,
        end: Vec<Cell>,
        held: &[(usize, usize)],
        changing: &[bool],
    ) -> Vec<Cell> {
        let labels = crate::mechanics::atom::rigid_parts(self.pos.len(), held, changing);
        let mut size: FxHashMap<usize, (usize, usize)> = FxHashMap::default();
        for (a, &l) in labels.iter().enumerate() {
            size.entry(l).or_insert((0, a)).0 += 1;
        }
        let Some(&(_, frame)) = size
            .values()
            .max_by_key(|&&(count, first)| (count, std::cmp::Reverse(first)))
        else {
            return end;
        };
        self.anchors = vec![frame];
        let shift = end[frame] - self.pos[frame];
        end.into_iter().map(|e| e - shift).collect()
    }

    fn connectivity(&self, k: usize, held: &[(usize, usize)], out: &mut StepFindings) {
        let loose = loose_atoms(self.pos.len(), held, &self.anchors);
        if !loose.is_empty() {
            out.violations.push(
                Violation::new(
                    ViolationKind::Disconnected,
                    k,
                    format!(
                        "{} atom(s) are not attached to the rest of the robot during the step",
                        loose.len()
                    ),
                )
                .modules(loose.iter().map(|&a| self.ids[a])),
            );
        }
    }

    fn collisions(
        &self,
        k: usize,
        end: &[Cell],
        plan: &AtomPlan,
        active: &[usize],
        eps: f64,
        out: &mut StepFindings,
    ) {
        if active.is_empty() {
            return;
        }
        let boxes = |a: usize| atom_boxes(self.pos[a], end[a], &self.ext[a], &plan.ext1[a]);
        let is_active: FxHashSet<usize> = active.iter().copied().collect();
        // Buckets of 4 units: a resting atom with its arms spans 3.
        let bucket = |v: f64| (v / 4.0).floor() as i32;
        let mut grid: FxHashMap<(i32, i32, i32), Vec<usize>> = FxHashMap::default();
        let mut hull_of: Vec<([f64; 3], [f64; 3])> = Vec::with_capacity(self.pos.len());
        for a in 0..self.pos.len() {
            let (lo, hi) = sweep_hull(&boxes(a));
            hull_of.push((lo, hi));
            for x in bucket(lo[0])..=bucket(hi[0]) {
                for y in bucket(lo[1])..=bucket(hi[1]) {
                    for z in bucket(lo[2])..=bucket(hi[2]) {
                        grid.entry((x, y, z)).or_default().push(a);
                    }
                }
            }
        }
        let mut seen: FxHashSet<(usize, usize)> = FxHashSet::default();
        let mut cells: Vec<&Vec<usize>> = grid.values().collect();
        cells.sort_by_key(|v| v.first().copied());
        for atoms in cells {
            for (i, &a) in atoms.iter().enumerate() {
                for &b in &atoms[i + 1..] {
                    if !(is_active.contains(&a) || is_active.contains(&b)) {
                        continue;
                    }
                    let p = pair(a, b);
                    if !seen.insert(p) {
                        continue;
                    }
                    let (ha, hb) = (hull_of[p.0], hull_of[p.1]);
                    if (0..3).any(|i| ha.1[i] <= hb.0[i] + eps || hb.1[i] <= ha.0[i] + eps) {
                        continue;
                    }
                    if let Some(v) = self.pair_collision(k, p, &boxes(p.0), &boxes(p.1), eps) {
                        out.violations.push(v);
                    }
                }
            }
        }
        out.violations
            .sort_by(|x, y| x.modules.cmp(&y.modules).then(x.kind.cmp(&y.kind)));
    }

    fn pair_collision(
        &self,
        k: usize,
        (a, b): (usize, usize),
        ba: &[(Option<Face>, MovingBox)],
        bb: &[(Option<Face>, MovingBox)],
        eps: f64,
    ) -> Option<Violation> {
        let part = |f: &Option<Face>| match f {
            None => "body".to_string(),
            Some(f) => format!("{} arm", f.name()),
        };
        for (fa, xa) in ba {
            for (fb, xb) in bb {
                if let Some((s, depth)) = first_overlap(xa, xb, eps) {
                    return Some(
                        Violation::new(
                            ViolationKind::Collision,
                            k,
                            format!(
                                "atom {}'s {} and atom {}'s {} interpenetrate by {:.3} at s = {:.3}",
                                self.ids[a],
                                part(fa),
                                self.ids[b],
                                part(fb),
                                depth,
                                s
                            ),
                        )
                        .modules([self.ids[a], self.ids[b]])
                        .detail("s", s)
                        .detail("depth", depth),
                    );
                }
            }
        }
        None
    }

    fn in_place(
        &self,
        k: usize,
        end: &[Cell],
        plan: &AtomPlan,
        active: &[usize],
        ch: &Checks,
        out: &mut StepFindings,
    ) {
        for &a in active {
            for (f, b) in atom_boxes(self.pos[a], end[a], &self.ext[a], &plan.ext1[a]) {
                let (lo, hi) = b.hull();
                if !within_union(lo, hi, ch.source_box, ch.target_box, ch.epsilon) {
                    out.violations.push(
                        Violation::new(
                            ViolationKind::OutOfPlace,
                            k,
                            format!(
                                "atom {}'s {} leaves the union of the source's and the target's bounding boxes",
                                self.ids[a],
                                f.map_or("body".to_string(), |f| format!("{} arm", f.name()))
                            ),
                        )
                        .modules([self.ids[a]])
                        .cells([self.pos[a], end[a]]),
                    );
                    break;
                }
            }
        }
    }

    fn mechanics(
        &self,
        k: usize,
        held: &[(usize, usize)],
        changing: &[bool],
        m: &AtomMechanics,
        out: &mut StepFindings,
    ) {
        if !changing.iter().any(|&c| c) {
            out.max_utilisation = Some(0.0);
            return;
        }
        let loads = crate::mechanics::atom::drive_loads(
            self.pos.len(),
            held,
            changing,
            self.anchors[0],
            m.drag,
        );
        let mut worst: f64 = 0.0;
        for l in loads {
            let u = l.force / m.strength;
            worst = if u.is_nan() { f64::NAN } else { worst.max(u) };
            // The one overload predicate: a NaN or infinite load fails.
            if crate::mechanics::overloaded(u) {
                let (a, b) = held[l.bond];
                out.violations.push(
                    Violation::new(
                        ViolationKind::Overload,
                        k,
                        format!(
                            "the arm between atoms {} and {} drags {} atom(s): {:.3} N against a face strength of {:.3} N",
                            self.ids[a], self.ids[b], l.atoms, l.force, m.strength
                        ),
                    )
                    .modules([self.ids[a], self.ids[b]])
                    .detail("utilisation", u),
                );
            }
        }
        out.max_utilisation = Some(worst);
    }

    /// The boxes of every body and resting arm, as one bounding box.
    pub fn bounding_box(&self) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for a in 0..self.pos.len() {
            for (_, b) in atom_boxes(self.pos[a], self.pos[a], &self.ext[a], &self.ext[a]) {
                for i in 0..3 {
                    lo[i] = lo[i].min(b.lo0[i]);
                    hi[i] = hi[i].max(b.hi0[i]);
                }
            }
        }
        (lo, hi)
    }
}

/// Atoms not connected to the first anchor through `bonds`.
pub fn loose_atoms(n: usize, bonds: &[(usize, usize)], anchors: &[usize]) -> Vec<usize> {
    if n == 0 {
        return Vec::new();
    }
    let mut adj = vec![Vec::new(); n];
    for &(a, b) in bonds {
        adj[a].push(b);
        adj[b].push(a);
    }
    let mut seen = vec![false; n];
    let root = anchors.first().copied().unwrap_or(0);
    let mut stack = vec![root];
    seen[root] = true;
    while let Some(u) = stack.pop() {
        for &v in &adj[u] {
            if !seen[v] {
                seen[v] = true;
                stack.push(v);
            }
        }
    }
    (0..n).filter(|&a| !seen[a]).collect()
}

/// The mechanics of the model file, as the atom check needs it.
#[derive(Clone, Debug)]
pub struct AtomMechanics {
    /// Friction force of one atom on the table, `μ_ground·m·g` (N).
    pub drag: f64,
    /// Face strength `p·L²` (N).
    pub strength: f64,
}

/// What the checks need besides the state.
#[derive(Clone, Debug)]
pub struct Checks {
    pub epsilon: f64,
    pub source_box: ([f64; 3], [f64; 3]),
    pub target_box: ([f64; 3], [f64; 3]),
    pub mechanics: Option<AtomMechanics>,
}

/// Certifies an atom schedule (the schedule's `atoms` must be set).
pub fn certify_atoms(s: &Schedule, rest: AtomRest, opts: &Options) -> Result<Report, InputError> {
    let start = AtomState::initial(s, rest)?;
    // The target: a kinematics-only pass to the end.
    let mut target = start.clone();
    for (k, step) in s.steps.iter().enumerate() {
        let plan = target.plan(k + 1, step)?;
        if target.advance(k + 1, plan, None).stop {
            break;
        }
    }
    let mechanics = if opts.lattice_only {
        None
    } else {
        match model_path(s, opts) {
            Some(path) => {
                let m = crate::mechanics::Model::load(&path)?;
                Some(AtomMechanics {
                    drag: m.ground.friction * m.mass * m.gravity,
                    strength: m.connector.tension(),
                })
            }
            None => None,
        }
    };
    let checks = Checks {
        epsilon: opts.epsilon.get(),
        source_box: start.bounding_box(),
        target_box: target.bounding_box(),
        mechanics,
    };
    let mut names: Vec<String> = CHECKS.iter().map(|c| c.to_string()).collect();
    names.push(if checks.mechanics.is_some() {
        MECHANICS.to_string()
    } else {
        super::MECHANICS_NOT_RUN.to_string()
    });
    let operations: usize = s.steps.iter().map(|st| st.events.len()).sum();
    let mut report = Report {
        format: REPORT_FORMAT.to_string(),
        version: 1,
        schedule: opts.name.clone(),
        lattice: s.lattice,
        modules: s.modules.len(),
        final_modules: s.modules.len(),
        steps: s.steps.len(),
        moves: operations,
        window: None,
        checks: names,
        load_factor_tolerance: 0.0,
        certified: false,
        stopped_at: None,
        violations: Vec::new(),
        warnings: Vec::new(),
        per_step: Vec::with_capacity(s.steps.len()),
    };
    let mut state = start;
    let all: Vec<(usize, usize)> = state.bonds.iter().copied().collect();
    let loose = loose_atoms(state.pos.len(), &all, &state.anchors);
    if !loose.is_empty() {
        report.violations.push(
            Violation::new(
                ViolationKind::Disconnected,
                0,
                format!(
                    "{} atom(s) of the initial robot are not attached to the rest",
                    loose.len()
                ),
            )
            .modules(loose.iter().map(|&a| state.ids[a])),
        );
    }
    opts.progress
        .start("certifying atoms", s.steps.len() as u64);
    for (k, step) in s.steps.iter().enumerate() {
        let plan = state.plan(k + 1, step)?;
        let ops = plan.operations;
        let found = state.advance(k + 1, plan, Some(&checks));
        let mut metrics = std::collections::BTreeMap::new();
        metrics.insert("atom_operations".to_string(), ops as f64);
        if let Some(u) = found.max_utilisation {
            metrics.insert("max_utilisation".to_string(), u);
        }
        report.per_step.push(StepResult {
            step: k + 1,
            moves: ops,
            violations: found.violations.len(),
            warnings: 0,
            metrics,
        });
        report.violations.extend(found.violations);
        opts.progress.advance(1);
        if found.stop {
            report.stopped_at = Some(k + 1);
            break;
        }
    }
    opts.progress.finish();
    report.certified = report.violations.is_empty() && report.stopped_at.is_none();
    Ok(report)
}
