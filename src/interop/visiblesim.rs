//! VisibleSim configuration files (`config.xml`), in and out.
//!
//! VisibleSim numbers the cells of Catoms3D worlds in one of two grids
//! (SPEC §1): the non-skewed `FCCLattice`, which is this crate's frame
//! (odd layers shifted by (½, ½)), and the skewed `SkewFCCLattice` of the
//! scaffold application (seed 000), whose `+z` step is the Z branch. The
//! XML does not say which one a run used (the application's code does),
//! so the mode is an explicit option ([`VsLattice`], default the
//! non-skewed FCC) and is never guessed.
//!
//! Block ids are VisibleSim's: in the default `ids="ORDERED"` mode the
//! blocks are numbered 1…n in reading order, `<block>` elements first,
//! then `<blocksLine>`, then `<blockBox>`; `ids="MANUAL"` reads each
//! block's `id`. Colours, orientations and the target list cannot change a
//! certification and are kept verbatim in the schedule's `meta`, so that
//! an import followed by an export gives back the configuration.

use crate::error::InputError;
use crate::lattice::{Cell, FccLattice, Ground, LatticeKind};
use crate::schedule::{Event, Length, ModuleSpec, Schedule};
use glam::DVec3;
use roxmltree::{Document, Node};
use serde_json::{Value, json};
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// Which of VisibleSim's two Catoms3D grids a file's positions are in.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum VsLattice {
    /// `FCCLattice`: this crate's frame, cell for cell (the default of
    /// Catoms3D worlds, and webots-visiblesim's frame).
    #[default]
    Fcc,
    /// `SkewFCCLattice` (seed 000's scaffold applications).
    SkewedFcc,
}

impl VsLattice {
    pub fn name(self) -> &'static str {
        match self {
            VsLattice::Fcc => "fcc",
            VsLattice::SkewedFcc => "skewed-fcc",
        }
    }

    /// A VisibleSim grid position as this crate's cell.
    pub fn to_cell(self, p: [i32; 3]) -> Cell {
        match self {
            VsLattice::Fcc => Cell::new(p[0], p[1], p[2]),
            VsLattice::SkewedFcc => FccLattice::from_skewed(p[0], p[1], p[2]),
        }
    }

    /// This crate's cell as a VisibleSim grid position.
    pub fn to_grid(self, c: Cell) -> [i32; 3] {
        match self {
            VsLattice::Fcc => [c.x, c.y, c.z],
            VsLattice::SkewedFcc => {
                let (x, y, z) = FccLattice::to_skewed(c);
                [x, y, z]
            }
        }
    }

    /// Whether grid position `p` lies in VisibleSim's grid of size `g`
    /// (`isInGrid`): `0 ≤ p < g` on the FCC lattice; on the skewed one
    /// layer z spans x, y in `[−⌊z/2⌋, g − ⌊z/2⌋)` (`SkewFCCLattice::
    /// getGridLowerBounds`), the same straight box in our frame.
    pub fn in_grid(self, p: [i32; 3], g: [i32; 3]) -> bool {
        let h = match self {
            VsLattice::Fcc => 0,
            VsLattice::SkewedFcc => p[2].max(0) / 2,
        };
        (0..2).all(|k| p[k] >= -h && p[k] < g[k] - h) && p[2] >= 0 && p[2] < g[2]
    }

    /// VisibleSim's `gridToUnscaledWorldPosition`: its world frame puts a
    /// cell's centre at our centre plus (½, ½, √2/4) (the corner of the
    /// grid is at the origin).
    pub(crate) fn unscaled_world(self, p: [i32; 3]) -> DVec3 {
        let z = (p[2] as f64 + 0.5) * std::f64::consts::FRAC_1_SQRT_2;
        match self {
            VsLattice::Fcc => {
                let off = if p[2].rem_euclid(2) == 0 { 0.5 } else { 1.0 };
                DVec3::new(p[0] as f64 + off, p[1] as f64 + off, z)
            }
            VsLattice::SkewedFcc => DVec3::new(
                p[0] as f64 + 0.5 + p[2] as f64 / 2.0,
                p[1] as f64 + 0.5 + p[2] as f64 / 2.0,
                z,
            ),
        }
    }
}

impl std::str::FromStr for VsLattice {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "fcc" => Ok(VsLattice::Fcc),
            "skewed-fcc" | "skewed" => Ok(VsLattice::SkewedFcc),
            other => Err(format!(
                "unknown VisibleSim lattice '{other}' (known: fcc, skewed-fcc)"
            )),
        }
    }
}

/// Which layer is the ground of an imported configuration.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum GroundChoice {
    /// The lowest occupied layer rests on the ground (VisibleSim draws its
    /// floor under the structure).
    #[default]
    Lowest,
    /// This layer (in VisibleSim's z, which both grids share).
    Layer(i32),
    /// No ground: a free-floating structure.
    None,
}

impl GroundChoice {
    pub fn resolve(self, cells: impl Iterator<Item = Cell>) -> Option<Ground> {
        match self {
            GroundChoice::Lowest => cells.map(|c| c.z).min().map(|layer| Ground { layer }),
            GroundChoice::Layer(layer) => Some(Ground { layer }),
            GroundChoice::None => None,
        }
    }
}

/// One block of a configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct VsBlock {
    pub id: u32,
    /// Position in the file's grid (see [`VsLattice`]).
    pub position: [i32; 3],
    /// The `color` attribute, verbatim.
    pub color: Option<String>,
    /// Catoms3D orientation code (0–23), which fixes connector numbering.
    pub orientation: Option<u8>,
    pub master: bool,
    /// Line of the element in the file.
    pub line: u32,
}

/// A VisibleSim configuration file, read.
#[derive(Clone, Debug, PartialEq)]
pub struct VsConfig {
    pub grid_size: [i32; 3],
    /// The `<blockList>` attributes, verbatim (colour, block size).
    pub block_list_attrs: BTreeMap<String, String>,
    pub blocks: Vec<VsBlock>,
    /// The `<targetList>` element, verbatim.
    pub target_list: Option<String>,
    /// The attributes of the first `<csg>` target (`content`, `translate`,
    /// `boundingBox`, …), verbatim, and its line.
    pub csg: Option<CsgAttrs>,
}

/// An input error at an XML node: line, column and element named.
fn at(doc: &Document, node: Node, msg: impl std::fmt::Display) -> InputError {
    let p = doc.text_pos_at(node.range().start);
    let name = if node.is_element() {
        format!("<{}>", node.tag_name().name())
    } else {
        "text".to_string()
    };
    InputError::new(format!(
        "line {}, column {}, element {name}: {msg}",
        p.row, p.col
    ))
}

fn line_of(doc: &Document, node: Node) -> u32 {
    doc.text_pos_at(node.range().start).row
}

/// Line numbers by binary search over the line starts: roxmltree's
/// `text_pos_at` scans from the start of the text, which made reading a
/// file of 223,113 blocks quadratic (262 s).
struct LineIndex(Vec<usize>);

impl LineIndex {
    fn new(text: &str) -> Self {
        let mut starts = vec![0];
        starts.extend(text.match_indices('\n').map(|(k, _)| k + 1));
        LineIndex(starts)
    }
    fn line(&self, node: Node) -> u32 {
        let at = node.range().start;
        u32::try_from(self.0.partition_point(|&s| s <= at)).unwrap_or(u32::MAX)
    }
}

/// Three comma-separated integers, strictly (VisibleSim's `atoi` would
/// read "1.5" as 1: a silent approximation refused here).
fn ints3(s: &str) -> Option<[i32; 3]> {
    let v: Vec<i32> = s
        .split(',')
        .map(|t| t.trim().parse::<i32>())
        .collect::<Result<_, _>>()
        .ok()?;
    v.try_into().ok()
}

/// Three comma-separated finite numbers.
fn floats3(s: &str) -> Option<[f64; 3]> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .ok()?;
    let a: [f64; 3] = v.try_into().ok()?;
    a.iter().all(|x| x.is_finite()).then_some(a)
}

/// Refuses attributes the reader does not know, so that a typo or an
/// unsupported feature is never dropped silently.
fn known_attrs(doc: &Document, node: Node, known: &[&str]) -> Result<(), InputError> {
    for a in node.attributes() {
        if !known.contains(&a.name()) {
            return Err(at(
                doc,
                node,
                format!(
                    "unknown attribute '{}' (known: {})",
                    a.name(),
                    known.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

/// Largest grid side accepted: far beyond any simulated world, well inside
/// the schedule's coordinate range.
const MAX_GRID: i32 = 1 << 16;

/// Reads a VisibleSim configuration. `lattice` is needed only by
/// `<blockBox>`, whose box is in world units.
pub fn read_config(text: &str, path: &Path, lattice: VsLattice) -> Result<VsConfig, InputError> {
    let opts = roxmltree::ParsingOptions {
        allow_dtd: true,
        ..Default::default()
    };
    let doc = Document::parse_with_options(text, opts)
        .map_err(|e| InputError::new(format!("malformed XML: {e}")).in_file(path))?;
    read_doc(&doc, lattice).map_err(|e| e.in_file(path))
}

fn read_doc(doc: &Document, lattice: VsLattice) -> Result<VsConfig, InputError> {
    let world = doc.root_element();
    if world.tag_name().name() != "world" {
        return Err(at(doc, world, "the root element must be <world>"));
    }
    let gs = world
        .attribute("gridSize")
        .ok_or_else(|| at(doc, world, "missing gridSize=\"x,y,z\""))?;
    let grid_size = ints3(gs)
        .filter(|g| g.iter().all(|&v| (1..=MAX_GRID).contains(&v)))
        .ok_or_else(|| {
            at(
                doc,
                world,
                format!("gridSize '{gs}' is not three integers in 1..={MAX_GRID}"),
            )
        })?;
    let mut cfg = VsConfig {
        grid_size,
        block_list_attrs: BTreeMap::new(),
        blocks: Vec::new(),
        target_list: None,
        csg: None,
    };
    let mut block_list = None;
    for child in world.children().filter(|n| n.is_element()) {
        match child.tag_name().name() {
            // Display settings: they cannot change a certification.
            "camera" | "spotlight" => {}
            "blockList" => {
                if block_list.replace(child).is_some() {
                    return Err(at(doc, child, "a second <blockList>"));
                }
            }
            "targetList" => {
                cfg.target_list = Some(text_of(doc, child));
                cfg.csg = find_csg(doc, child)?;
            }
            other if other.ends_with("List") => {
                return Err(at(
                    doc,
                    child,
                    format!(
                        "unknown block type list <{other}>: this reader takes Catoms3D worlds \
                         (<blockList>)"
                    ),
                ));
            }
            other => {
                return Err(at(
                    doc,
                    child,
                    format!("unknown element <{other}> in <world>"),
                ));
            }
        }
    }
    let Some(list) = block_list else {
        return Err(at(doc, world, "no <blockList>"));
    };
    read_blocks(doc, list, lattice, &mut cfg)?;
    Ok(cfg)
}

fn text_of(doc: &Document, node: Node) -> String {
    doc.input_text()[node.range()].to_string()
}

/// A `<csg>` element's attributes and its line.
type CsgAttrs = (BTreeMap<String, String>, u32);

fn find_csg(doc: &Document, list: Node) -> Result<Option<CsgAttrs>, InputError> {
    for target in list.children().filter(|n| n.is_element()) {
        if target.tag_name().name() != "target" {
            return Err(at(doc, target, "expected <target> in <targetList>"));
        }
        if target.attribute("format") != Some("csg") {
            continue;
        }
        let Some(csg) = target
            .children()
            .find(|n| n.is_element() && n.tag_name().name() == "csg")
        else {
            return Err(at(doc, target, "a csg target without a <csg> element"));
        };
        known_attrs(
            doc,
            csg,
            &["content", "translate", "boundingBox", "offset", "file"],
        )?;
        let attrs: BTreeMap<String, String> = csg
            .attributes()
            .map(|a| (a.name().to_string(), a.value().to_string()))
            .collect();
        return Ok(Some((attrs, line_of(doc, csg))));
    }
    Ok(None)
}

fn read_blocks(
    doc: &Document,
    list: Node,
    lattice: VsLattice,
    cfg: &mut VsConfig,
) -> Result<(), InputError> {
    known_attrs(
        doc,
        list,
        &["color", "blocksize", "blockSize", "ids", "seed"],
    )?;
    let manual = match list.attribute("ids") {
        None | Some("ORDERED") => false,
        Some("MANUAL") => true,
        Some(other) => {
            return Err(at(
                doc,
                list,
                format!(
                    "ids=\"{other}\": only ORDERED and MANUAL ids can be reproduced \
                     (RANDOM ids depend on VisibleSim's random generator)"
                ),
            ));
        }
    };
    cfg.block_list_attrs = list
        .attributes()
        .map(|a| (a.name().to_string(), a.value().to_string()))
        .collect();
    let scale = match list.attribute("blockSize").or(list.attribute("blocksize")) {
        Some(s) => floats3(s)
            .filter(|v| v.iter().all(|x| *x > 0.0))
            .ok_or_else(|| {
                at(
                    doc,
                    list,
                    format!("block size '{s}' is not three positive numbers"),
                )
            })?,
        None => [1.0; 3],
    };
    let lines = LineIndex::new(doc.input_text());
    let mut occupied: HashMap<[i32; 3], u32> = HashMap::new();
    let mut ids: std::collections::HashSet<u32> = std::collections::HashSet::new();
    let mut next_id = 0u32;
    let mut push = |cfg: &mut VsConfig, node: Node, b: VsBlock| -> Result<(), InputError> {
        let g = cfg.grid_size;
        if !lattice.in_grid(b.position, g) {
            return Err(at(
                doc,
                node,
                format!(
                    "position {:?} is outside the grid 0..{:?} (VisibleSim refuses it too)",
                    b.position, g
                ),
            ));
        }
        if let Some(other) = occupied.insert(b.position, b.id) {
            return Err(at(
                doc,
                node,
                format!(
                    "two blocks in one cell {:?}: block {} and block {other}",
                    b.position, b.id
                ),
            ));
        }
        if !ids.insert(b.id) {
            return Err(at(doc, node, format!("duplicate block id {}", b.id)));
        }
        cfg.blocks.push(b);
        Ok(())
    };
    // VisibleSim reads all <block>s, then all <blocksLine>s, then all
    // <blockBox>es: ids follow that order, not document order.
    for kind in ["block", "blocksLine", "blockBox"] {
        for node in list.children().filter(|n| n.is_element()) {
            let name = node.tag_name().name();
            if !["block", "blocksLine", "blockBox"].contains(&name) {
                return Err(at(
                    doc,
                    node,
                    format!(
                        "unknown element <{name}> in <blockList> (known: block, blocksLine, blockBox)"
                    ),
                ));
            }
            if name != kind {
                continue;
            }
            if manual && kind != "block" {
                return Err(at(
                    doc,
                    node,
                    format!("<{kind}> cannot be used with ids=\"MANUAL\" (as in VisibleSim)"),
                ));
            }
            let color = node.attribute("color").map(str::to_string);
            let line = lines.line(node);
            match kind {
                "block" => {
                    known_attrs(
                        doc,
                        node,
                        &["position", "color", "orientation", "master", "id"],
                    )?;
                    let ps = node
                        .attribute("position")
                        .ok_or_else(|| at(doc, node, "missing position=\"x,y,z\""))?;
                    let position = ints3(ps).ok_or_else(|| {
                        at(
                            doc,
                            node,
                            format!("position '{ps}' is not a lattice cell (three integers)"),
                        )
                    })?;
                    let orientation = match node.attribute("orientation") {
                        None => None,
                        Some(o) => {
                            Some(o.trim().parse::<u8>().ok().filter(|v| *v < 24).ok_or_else(
                                || at(doc, node, format!("orientation '{o}' is not a code 0..=23")),
                            )?)
                        }
                    };
                    let master = matches!(node.attribute("master"), Some("true" | "1"));
                    let id = if manual {
                        let s = node
                            .attribute("id")
                            .ok_or_else(|| at(doc, node, "ids=\"MANUAL\" needs an id"))?;
                        s.trim()
                            .parse::<u32>()
                            .ok()
                            .filter(|v| *v > 0)
                            .ok_or_else(|| {
                                at(doc, node, format!("id '{s}' is not a positive integer"))
                            })?
                    } else {
                        if node.attribute("id").is_some() {
                            return Err(at(doc, node, "an id needs ids=\"MANUAL\" on <blockList>"));
                        }
                        next_id += 1;
                        next_id
                    };
                    push(
                        cfg,
                        node,
                        VsBlock {
                            id,
                            position,
                            color,
                            orientation,
                            master,
                            line,
                        },
                    )?;
                }
                "blocksLine" => {
                    known_attrs(doc, node, &["line", "plane", "values", "color"])?;
                    let int = |a: &str| -> Result<i32, InputError> {
                        match node.attribute(a) {
                            None => Ok(0),
                            Some(s) => s
                                .trim()
                                .parse()
                                .map_err(|_| at(doc, node, format!("{a}='{s}' is not an integer"))),
                        }
                    };
                    let (y, z) = (int("line")?, int("plane")?);
                    let values = node.attribute("values").unwrap_or("");
                    for (x, ch) in values.chars().enumerate() {
                        match ch {
                            '1' => {
                                next_id += 1;
                                let x = i32::try_from(x).unwrap_or(i32::MAX);
                                push(
                                    cfg,
                                    node,
                                    VsBlock {
                                        id: next_id,
                                        position: [x, y, z],
                                        color: color.clone(),
                                        orientation: None,
                                        master: false,
                                        line,
                                    },
                                )?;
                            }
                            '0' => {}
                            other => {
                                return Err(at(
                                    doc,
                                    node,
                                    format!("values may hold only '0' and '1', found '{other}'"),
                                ));
                            }
                        }
                    }
                }
                _ => {
                    known_attrs(doc, node, &["boxOrigin", "boxSize", "color"])?;
                    let vec = |a: &str| -> Result<Option<[f64; 3]>, InputError> {
                        node.attribute(a)
                            .map(|s| {
                                floats3(s).ok_or_else(|| {
                                    at(doc, node, format!("{a}='{s}' is not three numbers"))
                                })
                            })
                            .transpose()
                    };
                    let origin = vec("boxOrigin")?.unwrap_or([0.0; 3]);
                    let g = cfg.grid_size;
                    let dest = match vec("boxSize")? {
                        Some(s) => [origin[0] + s[0], origin[1] + s[1], origin[2] + s[2]],
                        None => [
                            g[0] as f64 * scale[0],
                            g[1] as f64 * scale[1],
                            g[2] as f64 * scale[2],
                        ],
                    };
                    let cells = g[0] as u64 * g[1] as u64 * g[2] as u64;
                    if cells > 1 << 26 {
                        return Err(at(
                            doc,
                            node,
                            format!("a <blockBox> scans the whole grid: {cells} cells is too many"),
                        ));
                    }
                    for z in 0..g[2] {
                        for y in 0..g[1] {
                            for x in 0..g[0] {
                                let w =
                                    lattice.unscaled_world([x, y, z]) * DVec3::from_array(scale);
                                let inside = (0..3).all(|k| w[k] >= origin[k] && w[k] <= dest[k]);
                                if inside {
                                    next_id += 1;
                                    push(
                                        cfg,
                                        node,
                                        VsBlock {
                                            id: next_id,
                                            position: [x, y, z],
                                            color: color.clone(),
                                            orientation: None,
                                            master: false,
                                            line,
                                        },
                                    )?;
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    Ok(())
}

/// A configuration as a zero-step schedule (spacing `spacing`), with the
/// VisibleSim-only data in `meta.visiblesim`.
pub fn import_config(
    cfg: &VsConfig,
    lattice: VsLattice,
    ground: GroundChoice,
    spacing: Length,
    source: &str,
) -> Schedule {
    let mut s = Schedule::new(LatticeKind::Fcc, spacing);
    s.modules = cfg
        .blocks
        .iter()
        .map(|b| ModuleSpec {
            id: b.id,
            cell: lattice.to_cell(b.position),
            fixed: false,
        })
        .collect();
    s.ground = ground.resolve(s.modules.iter().map(|m| m.cell));
    let mut blocks = serde_json::Map::new();
    for b in &cfg.blocks {
        let mut o = serde_json::Map::new();
        if let Some(c) = &b.color {
            o.insert("color".into(), json!(c));
        }
        if let Some(k) = b.orientation {
            o.insert("orientation".into(), json!(k));
        }
        if b.master {
            o.insert("master".into(), json!(true));
        }
        if !o.is_empty() {
            blocks.insert(b.id.to_string(), Value::Object(o));
        }
    }
    let mut vs = serde_json::Map::new();
    vs.insert("source".into(), json!(source));
    vs.insert("lattice".into(), json!(lattice.name()));
    vs.insert("grid_size".into(), json!(cfg.grid_size));
    vs.insert("block_list".into(), json!(cfg.block_list_attrs));
    if !blocks.is_empty() {
        vs.insert("blocks".into(), Value::Object(blocks));
    }
    if let Some(t) = &cfg.target_list {
        vs.insert("target_list".into(), json!(t));
    }
    if let Some((csg, _)) = &cfg.csg {
        vs.insert("csg".into(), json!(csg));
    }
    s.meta.insert("visiblesim".into(), Value::Object(vs));
    s.meta.insert("imported_from".into(), json!("visiblesim"));
    s
}

/// The modules and their cells after `step` steps (0: the initial
/// configuration), replaying motions, entries and exits. Whether the moves
/// are feasible is the certifier's business; an event about a module that
/// is not there is unusable input.
pub fn config_at_step(s: &Schedule, step: usize) -> Result<BTreeMap<u32, Cell>, InputError> {
    if step > s.steps.len() {
        return Err(InputError::new(format!(
            "step {step} is beyond the schedule's {} steps",
            s.steps.len()
        )));
    }
    let mut at: BTreeMap<u32, Cell> = s.modules.iter().map(|m| (m.id, m.cell)).collect();
    for (k, st) in s.steps[..step].iter().enumerate() {
        for e in &st.events {
            let id = e.module();
            let unknown = || {
                InputError::new("the event names a module that is not in the scene")
                    .at_step(k + 1)
                    .for_module(id)
            };
            match e {
                Event::Rotate { to, .. } | Event::Slide { to, .. } => {
                    *at.get_mut(&id).ok_or_else(unknown)? = *to;
                }
                Event::Tunnel { path, .. } => {
                    let end = *path.last().ok_or_else(unknown)?;
                    *at.get_mut(&id).ok_or_else(unknown)? = end;
                }
                Event::Enter { cell, .. } | Event::Dock { cell, .. } => {
                    at.insert(id, *cell);
                }
                Event::Leave { .. } => {
                    at.remove(&id).ok_or_else(unknown)?;
                }
                Event::Attach { .. }
                | Event::Detach { .. }
                | Event::Expand { .. }
                | Event::Contract { .. } => {}
            }
        }
    }
    Ok(at)
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('"', "&quot;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// Writes the configuration of `s` after `step` steps as a VisibleSim
/// configuration in grid `lattice`. Blocks are written in ascending id
/// order as `<block>` elements, so VisibleSim's ORDERED numbering gives
/// them ids 1…n; a schedule whose ids are not 1…n gets a comment with the
/// renumbering. Data imported from VisibleSim (`meta.visiblesim`: grid
/// size, block list attributes, colours, orientations, targets) is written
/// back. A cell outside VisibleSim's grid (negative, or beyond the grid
/// size) is refused naming the module: shifting it would change the file's
/// meaning silently.
pub fn export_config(s: &Schedule, step: usize, lattice: VsLattice) -> Result<String, InputError> {
    if s.lattice != LatticeKind::Fcc {
        return Err(InputError::new(format!(
            "VisibleSim's Catoms3D worlds are FCC; this schedule is on the {} lattice",
            s.lattice.name()
        )));
    }
    let modules = config_at_step(s, step)?;
    let vs = s.meta.get("visiblesim").and_then(Value::as_object);
    let positions: Vec<(u32, [i32; 3])> = modules
        .iter()
        .map(|(&id, &c)| (id, lattice.to_grid(c)))
        .collect();
    let grid_size: [i32; 3] = match vs
        .and_then(|v| v.get("grid_size"))
        .and_then(|g| serde_json::from_value::<[i32; 3]>(g.clone()).ok())
    {
        Some(g) => g,
        None => {
            // Both grids are the same straight box in our frame.
            let mut g = [1; 3];
            for c in modules.values() {
                for (k, v) in [c.x, c.y, c.z].into_iter().enumerate() {
                    g[k] = g[k].max(v + 1);
                }
            }
            g
        }
    };
    for (id, p) in &positions {
        if !lattice.in_grid(*p, grid_size) {
            return Err(InputError::new(format!(
                "position {p:?} in VisibleSim's {} grid lies outside its grid 0..{grid_size:?}",
                lattice.name()
            ))
            .at_step(step)
            .for_module(*id));
        }
    }
    let mut out = String::new();
    out.push_str("<?xml version=\"1.0\" standalone=\"no\" ?>\n");
    out.push_str(&format!(
        "<!-- written by reconfcheck: {} modules after step {step}, VisibleSim grid {} -->\n",
        positions.len(),
        lattice.name()
    ));
    let renumbered = positions
        .iter()
        .enumerate()
        .any(|(k, (id, _))| *id as usize != k + 1);
    if renumbered {
        out.push_str("<!-- VisibleSim numbers blocks 1..n in this order; reconfcheck ids:");
        for (id, _) in &positions {
            out.push_str(&format!(" {id}"));
        }
        out.push_str(" -->\n");
    }
    out.push_str(&format!(
        "<world gridSize=\"{},{},{}\">\n",
        grid_size[0], grid_size[1], grid_size[2]
    ));
    let mut list_attrs = String::new();
    if let Some(attrs) = vs
        .and_then(|v| v.get("block_list"))
        .and_then(Value::as_object)
    {
        for (k, v) in attrs {
            if let Some(v) = v.as_str() {
                list_attrs.push_str(&format!(" {k}=\"{}\"", escape(v)));
            }
        }
    }
    out.push_str(&format!("  <blockList{list_attrs}>\n"));
    let blocks = vs.and_then(|v| v.get("blocks")).and_then(Value::as_object);
    for (id, p) in &positions {
        let mut attrs = format!("position=\"{},{},{}\"", p[0], p[1], p[2]);
        if let Some(b) = blocks.and_then(|b| b.get(&id.to_string())) {
            if let Some(c) = b.get("color").and_then(Value::as_str) {
                attrs.push_str(&format!(" color=\"{}\"", escape(c)));
            }
            if let Some(o) = b.get("orientation").and_then(Value::as_u64) {
                attrs.push_str(&format!(" orientation=\"{o}\""));
            }
            if b.get("master").and_then(Value::as_bool) == Some(true) {
                attrs.push_str(" master=\"true\"");
            }
        }
        out.push_str(&format!("    <block {attrs}/>\n"));
    }
    out.push_str("  </blockList>\n");
    if let Some(t) = vs
        .and_then(|v| v.get("target_list"))
        .and_then(Value::as_str)
    {
        out.push_str("  ");
        out.push_str(t);
        out.push('\n');
    }
    out.push_str("</world>\n");
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const CROSS: &str = r#"<?xml version="1.0" standalone="no" ?>
<world gridSize="20,20,10">
  <camera target="1,2,3" />
  <blockList color="128,128,128" blocksize="10,10,10">
    <block position="5,5,2" color="0,255,255" orientation="11" />
    <block position="6,5,2" />
  </blockList>
  <targetList>
    <target format="csg">
      <csg translate="5,5,2" content="cube([4, 4, 2], true);"/>
    </target>
  </targetList>
</world>
"#;

    fn read(text: &str) -> Result<VsConfig, InputError> {
        read_config(text, Path::new("t.xml"), VsLattice::Fcc)
    }

    #[test]
    fn blocks_keep_reading_order_ids_colours_and_the_csg_target() {
        let c = read(CROSS).unwrap();
        assert_eq!(c.grid_size, [20, 20, 10]);
        assert_eq!(c.blocks.len(), 2);
        assert_eq!(c.blocks[0].id, 1);
        assert_eq!(c.blocks[0].orientation, Some(11));
        assert_eq!(c.blocks[0].color.as_deref(), Some("0,255,255"));
        assert_eq!(c.blocks[1].position, [6, 5, 2]);
        let (csg, _) = c.csg.unwrap();
        assert_eq!(csg["translate"], "5,5,2");
    }

    /// VisibleSim's skewed grid starts layer z at x, y = −⌊z/2⌋: a block
    /// at (−1, −1, 2) is in it, one at (−1, 0, 1) is not.
    #[test]
    fn the_skewed_grid_is_a_straight_box_in_our_frame() {
        let xml = |p: &str| {
            format!(
                "<world gridSize=\"4,4,4\"><blockList><block position=\"{p}\"/></blockList></world>"
            )
        };
        let sk = |p: &str| read_config(&xml(p), Path::new("t.xml"), VsLattice::SkewedFcc);
        assert!(sk("-1,-1,2").is_ok());
        assert!(sk("2,2,3").is_ok() && sk("3,0,3").is_err());
        assert!(sk("-1,0,1").is_err());
        assert!(read("-1,-1,2").is_err());
        fn read(p: &str) -> Result<VsConfig, InputError> {
            read_config(
                &format!(
                    "<world gridSize=\"4,4,4\"><blockList><block position=\"{p}\"/></blockList></world>"
                ),
                Path::new("t.xml"),
                VsLattice::Fcc,
            )
        }
    }

    #[test]
    fn block_lines_are_the_lines_of_the_file() {
        let c = read(CROSS).unwrap();
        assert_eq!((c.blocks[0].line, c.blocks[1].line), (5, 6));
    }

    #[test]
    fn ids_follow_visiblesims_order_blocks_then_lines_then_boxes() {
        let c = read(
            r#"<world gridSize="5,5,5"><blockList>
                 <blocksLine line="1" plane="0" values="0110"/>
                 <block position="4,4,0"/>
               </blockList></world>"#,
        )
        .unwrap();
        let ids: Vec<(u32, [i32; 3])> = c.blocks.iter().map(|b| (b.id, b.position)).collect();
        assert_eq!(ids, vec![(1, [4, 4, 0]), (2, [1, 1, 0]), (3, [2, 1, 0])]);
    }

    #[test]
    fn the_skewed_grid_converts_to_our_frame_and_back() {
        for p in [[0, 0, 0], [3, 2, 1], [3, 2, 2], [5, 5, 7]] {
            let c = VsLattice::SkewedFcc.to_cell(p);
            assert_eq!(VsLattice::SkewedFcc.to_grid(c), p);
            // Same world point up to VisibleSim's constant offset.
            let ours = crate::lattice::Lattice::centre(&FccLattice, c);
            let theirs = VsLattice::SkewedFcc.unscaled_world(p);
            let off = theirs - ours;
            assert!((off - DVec3::new(0.5, 0.5, 0.5 / std::f64::consts::SQRT_2)).length() < 1e-12);
            let f = VsLattice::Fcc.unscaled_world(p)
                - crate::lattice::Lattice::centre(&FccLattice, VsLattice::Fcc.to_cell(p));
            assert!((f - off).length() < 1e-12);
        }
    }

    #[test]
    fn bad_configurations_name_line_and_element() {
        let cases = [
            (
                "<world gridSize=\"5,5,5\"><blockList><block position=\"1,1\"/></blockList></world>",
                "<block>",
            ),
            (
                "<world gridSize=\"5,5,5\"><blockList>\n<block position=\"1.5,1,0\"/></blockList></world>",
                "line 2",
            ),
            (
                "<world gridSize=\"5,5,5\"><blockList><block position=\"1,1,0\"/>\n<block position=\"1,1,0\"/></blockList></world>",
                "two blocks in one cell",
            ),
            (
                "<world gridSize=\"5,5,5\"><smartBlocksList/></world>",
                "unknown block type",
            ),
            (
                "<world gridSize=\"5,5,5\"><blockList><block position=\"9,1,0\"/></blockList></world>",
                "outside the grid",
            ),
            (
                "<world gridSize=\"5,5,5\"><blockList><block position=\"1,1,0\"></blockList></world>",
                "malformed XML",
            ),
            (
                "<world gridSize=\"5,5,5\"><blockList><block position=\"1,1,0\" orientaton=\"3\"/></blockList></world>",
                "unknown attribute",
            ),
        ];
        for (xml, want) in cases {
            let e = read(xml).unwrap_err();
            let msg = e.to_string();
            assert!(msg.contains(want), "{xml}: {msg}");
            assert!(msg.starts_with("t.xml: "), "{msg}");
            if !msg.contains("malformed") {
                assert!(msg.contains("line ") && msg.contains("element <"), "{msg}");
            }
        }
    }

    #[test]
    fn import_export_import_is_the_identity() {
        for lattice in [VsLattice::Fcc, VsLattice::SkewedFcc] {
            let c = read_config(CROSS, Path::new("t.xml"), lattice).unwrap();
            let s = import_config(&c, lattice, GroundChoice::Lowest, Length::mm(3.6), "t.xml");
            assert!(s.steps.is_empty());
            assert_eq!(s.ground, Some(Ground { layer: 2 }));
            let xml = export_config(&s, 0, lattice).unwrap();
            let c2 = read_config(&xml, Path::new("u.xml"), lattice).unwrap();
            let s2 = import_config(&c2, lattice, GroundChoice::Lowest, Length::mm(3.6), "t.xml");
            assert_eq!(s, s2, "{xml}");
        }
    }
}
