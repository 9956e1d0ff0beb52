//! VisibleSim's CSG dialect, read as VisibleSim reads it (its
//! `csgParser.cpp`, `csgUtils.cpp`, `csg.cpp` and `TargetCSG`):
//!
//! * cubes and cylinders are always centred, whatever flag follows;
//!   `cube(a, b, c, …)` and `cube([a, b, c], …)` are the same cube;
//! * `cylinder(a, b, …)` is height a and radius b; the rest is dropped
//!   (so `cylinder(20, 30, 0)`, an OpenSCAD cone, is a cylinder);
//! * `sphere(r, …)` reads its first parameter;
//! * parameters are evaluated, then stored as float32;
//! * `translate`, `scale` take three numbers with or without brackets and
//!   apply to the *next object only* (a `{` after them is refused: VisibleSim
//!   would transform the first object of the block and read the `}` as the
//!   end of the enclosing group);
//! * a difference's (and an intersection's) bounding box is its first
//!   child's, a union's the union of its children's;
//! * a grid cell g of the target is inside when the solid contains
//!   `W(g) + bb.P0 − translate` (W: VisibleSim's unscaled world position,
//!   bb.P0 the solid's bounding-box corner when `boundingBox` is true — the
//!   default — with a further −1 when `offset` is true), for g inside
//!   `gridSize` only (on the skewed lattice layer z spans x, y from
//!   −⌊z/2⌋, as `SkewFCCLattice::getGridLowerBounds` says).
//!
//! * `rotate(x, y, z)` (degrees) is `R = R_x(x)·R_y(y)·R_z(z)` (VisibleSim's
//!   `CSGRotate`: `rotate = rotate*mat` for x, then y, then z, row-major
//!   matrices acting on column vectors); a point is inside when the child
//!   contains `R⁻¹·p`; its bounding box is that of the two corners `R·P0`
//!   and `R·P1` only (VisibleSim's, not the box of the rotated solid: a
//!   45° turn of a cube gives a flat box — reproduced, since the target's
//!   cells depend on it).
//!
//! Not read (refused with line and column): a one-number `cube(s)`
//! (VisibleSim reads it as a degenerate cube), and anything else.

use super::csg_text::{Cursor, Tok, Tokens, lex};
use super::shape::{Shape, Skew};
use crate::error::InputError;
use glam::DVec3;

/// Where VisibleSim's `TargetCSG` asks its solid about a grid cell, less
/// the cell's unscaled world position: `bb.P0 − translate` (see the module
/// doc), from the `<csg>` element's `boundingBox`, `offset` and `translate`
/// attributes (`attr`), at `line` of its file.
pub fn target_shift<'a>(
    root: &VsNode,
    attr: impl Fn(&str) -> Option<&'a str>,
    line: usize,
) -> Result<DVec3, InputError> {
    let here = |m: String| InputError::new(format!("line {line}, element <csg>: {m}"));
    let flag = |k: &str, default: bool| match attr(k) {
        None => Ok(default),
        Some("true" | "1") => Ok(true),
        Some("false" | "0") => Ok(false),
        Some(o) => Err(here(format!("{k}=\"{o}\" is not true or false"))),
    };
    let translate = match attr("translate") {
        None => DVec3::ZERO,
        Some(s) => {
            let v: Vec<f64> = s
                .split(',')
                .map(|t| t.trim().parse::<f64>().ok().filter(|x| x.is_finite()))
                .collect::<Option<_>>()
                .filter(|v: &Vec<f64>| v.len() == 3)
                .ok_or_else(|| here(format!("translate '{s}' is not three numbers")))?;
            DVec3::new(v[0], v[1], v[2])
        }
    };
    let mut p0 = if flag("boundingBox", true)? {
        root.bounding_box().0
    } else {
        DVec3::ZERO
    };
    if flag("offset", false)? {
        p0 -= DVec3::ONE;
    }
    Ok(p0 - translate)
}

/// Deepest nesting of groups or expressions read (see the scaffold CSG
/// parser's `MAX_DEPTH`): deeper input is refused, never a stack overflow.
pub const MAX_VS_DEPTH: usize = 100;

/// A VisibleSim CSG solid.
#[derive(Clone, Debug, PartialEq)]
pub enum VsNode {
    /// Centred box with these sizes.
    Cube(DVec3),
    /// Centred cylinder along z.
    Cylinder {
        h: f64,
        r: f64,
    },
    Sphere(f64),
    Translate(DVec3, Box<VsNode>),
    Scale(DVec3, Box<VsNode>),
    /// `R` and its inverse (see the module doc).
    Rotate(glam::DMat3, glam::DMat3, Box<VsNode>),
    Union(Vec<VsNode>),
    Difference(Vec<VsNode>),
    Intersection(Vec<VsNode>),
}

impl VsNode {
    /// VisibleSim's `isInside` (closed solids, exact comparisons).
    pub fn contains(&self, p: DVec3) -> bool {
        match self {
            VsNode::Cube(s) => (p.abs() - *s / 2.0).cmple(DVec3::ZERO).all(),
            VsNode::Cylinder { h, r } => {
                p.z.abs() <= h / 2.0 && (p.x * p.x + p.y * p.y).sqrt() <= *r
            }
            VsNode::Sphere(r) => p.length() <= *r,
            VsNode::Translate(v, c) => c.contains(p - *v),
            VsNode::Scale(s, c) => c.contains(p / *s),
            VsNode::Rotate(_, inv, c) => c.contains(*inv * p),
            VsNode::Union(c) => c.iter().any(|n| n.contains(p)),
            VsNode::Difference(c) => {
                c.first().is_some_and(|f| f.contains(p)) && !c[1..].iter().any(|n| n.contains(p))
            }
            VsNode::Intersection(c) => c.iter().all(|n| n.contains(p)),
        }
    }

    /// VisibleSim's `boundingBox` (lower and upper corners).
    pub fn bounding_box(&self) -> (DVec3, DVec3) {
        match self {
            VsNode::Cube(s) => (-*s / 2.0, *s / 2.0),
            VsNode::Cylinder { h, r } => {
                (DVec3::new(-r, -r, -h / 2.0), DVec3::new(*r, *r, h / 2.0))
            }
            VsNode::Sphere(r) => (DVec3::splat(-r), DVec3::splat(*r)),
            VsNode::Translate(v, c) => {
                let (a, b) = c.bounding_box();
                (a + *v, b + *v)
            }
            VsNode::Scale(s, c) => {
                let (a, b) = c.bounding_box();
                (a * *s, b * *s)
            }
            VsNode::Rotate(r, _, c) => {
                let (a, b) = c.bounding_box();
                let (p0, p1) = (*r * a, *r * b);
                (p0.min(p1), p0.max(p1))
            }
            VsNode::Union(c) => c
                .iter()
                .map(VsNode::bounding_box)
                .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)))
                .unwrap_or_default(),
            VsNode::Difference(c) | VsNode::Intersection(c) => {
                c.first().map(VsNode::bounding_box).unwrap_or_default()
            }
        }
    }
}

struct Parser {
    t: Tokens,
    /// Line offset of the CSG text in its file (the `<csg>` element's line).
    line0: usize,
}

/// One argument: a number, a bracketed vector, or a flag (ignored).
enum Arg {
    Num(f64),
    Vec(Vec<f64>),
    Flag,
}

impl Cursor for Parser {
    fn tokens(&self) -> &Tokens {
        &self.t
    }
    fn tokens_mut(&mut self) -> &mut Tokens {
        &mut self.t
    }
    fn max_depth(&self) -> usize {
        MAX_VS_DEPTH
    }
    fn err(&self, msg: impl std::fmt::Display) -> InputError {
        let (l, c) = self.here().unwrap_or((1, 0));
        InputError::new(format!(
            "CSG line {}, column {c}: {msg}",
            l + self.line0.saturating_sub(1)
        ))
    }
}

impl Parser {
    fn object(&mut self) -> Result<VsNode, InputError> {
        self.deeper()?;
        let n = self.object_inner();
        self.t.depth -= 1;
        n
    }

    fn object_inner(&mut self) -> Result<VsNode, InputError> {
        let start = self.t.pos;
        let Some(Tok::Id(name)) = self.peek().cloned() else {
            return Err(self.err("expected a CSG object"));
        };
        self.t.pos += 1;
        let args = self.args()?;
        // Parameters as VisibleSim stores them: float32.
        let nums: Vec<f64> = args
            .iter()
            .flat_map(|a| match a {
                Arg::Num(v) => vec![*v],
                Arg::Vec(v) => v.clone(),
                Arg::Flag => vec![],
            })
            .map(|v| v as f32 as f64)
            .collect();
        let at_start = |p: &mut Parser, msg: String| {
            p.t.pos = start;
            p.err(msg)
        };
        let three = |p: &mut Parser, nums: &[f64]| -> Result<DVec3, InputError> {
            if nums.len() < 3 {
                return Err(at_start(
                    p,
                    format!("{name} needs three numbers (VisibleSim reads fewer as garbage)"),
                ));
            }
            Ok(DVec3::new(nums[0], nums[1], nums[2]))
        };
        let node = match name.as_str() {
            "cube" => {
                let s = three(self, &nums)?;
                self.end()?;
                VsNode::Cube(s)
            }
            "cylinder" => {
                if nums.len() < 2 {
                    return Err(at_start(
                        self,
                        "cylinder needs a height and a radius".into(),
                    ));
                }
                self.end()?;
                VsNode::Cylinder {
                    h: nums[0],
                    r: nums[1],
                }
            }
            "sphere" => {
                let Some(&r) = nums.first() else {
                    return Err(at_start(self, "sphere needs a radius".into()));
                };
                self.end()?;
                VsNode::Sphere(r)
            }
            "translate" | "scale" | "rotate" => {
                let v = three(self, &nums)?;
                // VisibleSim skips ';' like a space: `scale([2,2,2]); sphere(10);`
                // scales the sphere.
                while self.eat(';') {}
                if self.peek() == Some(&Tok::Sym('{')) {
                    return Err(self.err(format!(
                        "VisibleSim applies {name} to the next object only and reads this block's \
                         '}}' as the end of the enclosing group: write one object after {name}, \
                         or a union() around several"
                    )));
                }
                let child = Box::new(self.object()?);
                if name == "translate" {
                    VsNode::Translate(v, child)
                } else if name == "rotate" {
                    let deg = |a: f64| a.to_radians();
                    let r = glam::DMat3::from_rotation_x(deg(v.x))
                        * glam::DMat3::from_rotation_y(deg(v.y))
                        * glam::DMat3::from_rotation_z(deg(v.z));
                    VsNode::Rotate(r, r.inverse(), child)
                } else {
                    if v.cmpeq(DVec3::ZERO).any() {
                        return Err(at_start(self, "scale by zero".into()));
                    }
                    VsNode::Scale(v, child)
                }
            }
            "color" => {
                // Colour only: VisibleSim's membership ignores it.
                if self.peek() == Some(&Tok::Sym('{')) {
                    return Err(self.err("a block after color(): write one object"));
                }
                self.object()?
            }
            "union" | "difference" | "intersection" => {
                if !nums.is_empty() {
                    return Err(at_start(self, format!("{name}() takes no parameters")));
                }
                self.expect('{')?;
                let mut c = Vec::new();
                while !self.eat('}') {
                    if self.peek().is_none() {
                        return Err(self.err("missing '}'"));
                    }
                    if self.eat(';') {
                        continue;
                    }
                    c.push(self.object()?);
                }
                match name.as_str() {
                    "union" => VsNode::Union(c),
                    "difference" => VsNode::Difference(c),
                    _ => VsNode::Intersection(c),
                }
            }
            other => {
                return Err(at_start(
                    self,
                    format!(
                        "'{other}' is not a VisibleSim CSG object (known: cube, cylinder, sphere, \
                         translate, scale, rotate, color, union, difference, intersection)"
                    ),
                ));
            }
        };
        Ok(node)
    }

    /// After a primitive: an optional ';'.
    fn end(&mut self) -> Result<(), InputError> {
        self.eat(';');
        Ok(())
    }

    fn args(&mut self) -> Result<Vec<Arg>, InputError> {
        self.expect('(')?;
        let mut out = Vec::new();
        if self.eat(')') {
            return Ok(out);
        }
        loop {
            // `center = true`: VisibleSim ignores named flags too.
            if let (Some(Tok::Id(_)), Some((Tok::Sym('='), _, _))) =
                (self.peek().cloned(), self.t.toks.get(self.t.pos + 1))
            {
                self.t.pos += 2;
            }
            let a = if matches!(self.peek(), Some(Tok::Id(s)) if s == "true" || s == "false") {
                self.t.pos += 1;
                Arg::Flag
            } else if self.eat('[') {
                let mut v = vec![self.expr()?];
                while self.eat(',') {
                    v.push(self.expr()?);
                }
                self.expect(']')?;
                Arg::Vec(v)
            } else {
                Arg::Num(self.expr()?)
            };
            out.push(a);
            if self.eat(')') {
                return Ok(out);
            }
            self.expect(',')?;
        }
    }
}

/// Parses the `content` of a `<csg>` target. `line0` is the line of the
/// `<csg>` element in its file, so that errors name the file's line.
pub fn parse_vs_csg(text: &str, line0: usize) -> Result<VsNode, InputError> {
    let mut p = Parser {
        t: Tokens::new(lex(text).map_err(|e| {
            InputError::new(format!("CSG (starting at line {line0}): {}", e.message))
        })?),
        line0,
    };
    let mut nodes = Vec::new();
    while !p.t.at_end() {
        if p.eat(';') {
            continue;
        }
        nodes.push(p.object()?);
    }
    match nodes.len() {
        0 => Err(InputError::new(format!(
            "the <csg> target at line {line0} defines no solid"
        ))),
        1 => Ok(nodes.pop().expect("one node")),
        // VisibleSim keeps only the first top-level object.
        _ => {
            p.t.pos = 0;
            Err(InputError::new(format!(
                "the <csg> target at line {line0} has {} top-level objects; VisibleSim reads only \
                 the first: wrap them in union() {{ … }}",
                nodes.len()
            )))
        }
    }
}

/// A VisibleSim configuration's CSG target as a scaffold goal shape, as
/// the authors' `scaffolding_csg` application asks it: the scaffold's
/// skewed cell s is VisibleSim's skewed grid cell `s + (3, 3, 3)` (its
/// `sbSeedPos`), inside when `TargetCSG::isInTarget` says so.
#[derive(Clone, Debug)]
pub struct VsCsgShape {
    pub name: String,
    pub root: VsNode,
    /// bb.P0 (− 1 with `offset`) − translate: added to W(g).
    pub shift: DVec3,
    pub grid_size: [i32; 3],
}

/// The authors' scaffold seed position in VisibleSim's skewed grid.
pub const SEED: [i32; 3] = [3, 3, 3];

impl VsCsgShape {
    /// VisibleSim's skewed `gridToUnscaledWorldPosition`.
    fn world(g: [i32; 3]) -> DVec3 {
        DVec3::new(
            g[0] as f64 + 0.5 + g[2] as f64 / 2.0,
            g[1] as f64 + 0.5 + g[2] as f64 / 2.0,
            (g[2] as f64 + 0.5) * std::f64::consts::FRAC_1_SQRT_2,
        )
    }

    /// Whether VisibleSim's skewed grid cell g is in the target.
    pub fn contains_grid(&self, g: [i32; 3]) -> bool {
        let h = g[2].max(0) / 2;
        let in_grid = g[2] >= 0
            && g[2] < self.grid_size[2]
            && (0..2).all(|k| g[k] >= -h && g[k] < self.grid_size[k] - h);
        in_grid && self.root.contains(Self::world(g) + self.shift)
    }

    /// Reads the first CSG target of a VisibleSim configuration file.
    pub fn load(path: &std::path::Path) -> Result<VsCsgShape, InputError> {
        let text = crate::error::read_file(path, "VisibleSim configuration")?;
        let doc = roxmltree::Document::parse_with_options(
            &text,
            roxmltree::ParsingOptions {
                allow_dtd: true,
                ..Default::default()
            },
        )
        .map_err(|e| InputError::new(format!("malformed XML: {e}")).in_file(path))?;
        let world = doc.root_element();
        let grid_size = world
            .attribute("gridSize")
            .and_then(|s| {
                let v: Vec<i32> = s
                    .split(',')
                    .map(|t| t.trim().parse().ok())
                    .collect::<Option<_>>()?;
                <[i32; 3]>::try_from(v).ok()
            })
            .filter(|g| g.iter().all(|&v| (1..=1 << 16).contains(&v)))
            .ok_or_else(|| InputError::new("<world> has no valid gridSize").in_file(path))?;
        let csg = doc
            .descendants()
            .find(|n| {
                n.has_tag_name("csg")
                    && n.parent_element().is_some_and(|t| {
                        t.has_tag_name("target") && t.attribute("format") == Some("csg")
                    })
            })
            .ok_or_else(|| InputError::new("the configuration has no CSG target").in_file(path))?;
        let line = doc.text_pos_at(csg.range().start).row as usize;
        let here =
            |m: String| InputError::new(format!("line {line}, element <csg>: {m}")).in_file(path);
        let content = csg
            .attribute("content")
            .ok_or_else(|| here("no content".into()))?;
        let root = parse_vs_csg(content, line).map_err(|e| e.in_file(path))?;
        let shift = target_shift(&root, |k| csg.attribute(k), line).map_err(|e| e.in_file(path))?;
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        Ok(VsCsgShape {
            name,
            root,
            shift,
            grid_size,
        })
    }

    /// Scaffold-frame bounds covering every target cell of the grid
    /// (one cell of margin), or `None` when the target is empty.
    pub fn skew_bounds(&self) -> Option<(Skew, Skew)> {
        let g = self.grid_size;
        let (mut lo, mut hi): (Option<[i32; 3]>, [i32; 3]) = (None, [i32::MIN; 3]);
        for z in 0..g[2] {
            let h = z / 2;
            for y in -h..g[1] - h {
                for x in -h..g[0] - h {
                    if self.contains_grid([x, y, z]) {
                        let p = [x - SEED[0], y - SEED[1], z - SEED[2]];
                        let l = lo.get_or_insert(p);
                        for k in 0..3 {
                            l[k] = l[k].min(p[k]);
                            hi[k] = hi[k].max(p[k]);
                        }
                    }
                }
            }
        }
        let lo = lo?;
        Some((
            Skew::new(lo[0] - 1, lo[1] - 1, lo[2].min(0)),
            Skew::new(hi[0] + 1, hi[1] + 1, hi[2] + 1),
        ))
    }
}

impl Shape for VsCsgShape {
    fn contains(&self, c: Skew) -> bool {
        self.contains_grid([c.x + SEED[0], c.y + SEED[1], c.z + SEED[2]])
    }
    fn describe(&self) -> String {
        format!("VisibleSim CSG target '{}'", self.name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cubes_and_cylinders_are_centred_and_cylinders_read_height_then_radius() {
        let c = parse_vs_csg("cube([4, 2, 2]);", 1).unwrap();
        assert_eq!(c, parse_vs_csg("cube(4, 2, 2, false);", 1).unwrap());
        assert!(c.contains(DVec3::new(-1.9, 0.0, 0.0)));
        let cone = parse_vs_csg("cylinder(20, 30, 0);", 1).unwrap();
        assert_eq!(cone, VsNode::Cylinder { h: 20.0, r: 30.0 });
        let t = parse_vs_csg("translate(1,2,3) sphere(2, true);", 1).unwrap();
        assert_eq!(
            t,
            VsNode::Translate(DVec3::new(1.0, 2.0, 3.0), Box::new(VsNode::Sphere(2.0)))
        );
        // float32: 0.1 is stored as 0.100000001490116…
        let f = parse_vs_csg("sphere(0.1);", 1).unwrap();
        assert_eq!(f, VsNode::Sphere(0.1f32 as f64));
        // A ';' after a transform is skipped, as VisibleSim skips it.
        let s = parse_vs_csg("scale([2,2,2]); sphere(10, true);", 1).unwrap();
        assert_eq!(
            s,
            VsNode::Scale(DVec3::splat(2.0), Box::new(VsNode::Sphere(10.0)))
        );
    }

    #[test]
    fn a_difference_takes_its_first_childs_bounding_box() {
        let d = parse_vs_csg(
            "difference() { cube([4,4,4], true); translate([5,0,0]) cube([8,8,8], true); }",
            1,
        )
        .unwrap();
        assert_eq!(d.bounding_box(), (DVec3::splat(-2.0), DVec3::splat(2.0)));
    }

    #[test]
    fn rotate_is_visiblesims_rx_ry_rz_with_its_two_corner_bounding_box() {
        // A quarter turn about z takes the long x side of the cube to y.
        let s = parse_vs_csg("rotate([0,0,90]) cube([4,2,2]);", 1).unwrap();
        assert!(s.contains(DVec3::new(0.0, 1.9, 0.0)));
        assert!(!s.contains(DVec3::new(1.9, 0.0, 0.0)));
        let (a, b) = s.bounding_box();
        assert!((a - DVec3::new(-1.0, -2.0, -1.0)).length() < 1e-12, "{a}");
        assert!((b - DVec3::new(1.0, 2.0, 1.0)).length() < 1e-12, "{b}");
        // The order: x first, then y, then z (R = Rx·Ry·Rz acting on the
        // child's points). Rx(90)·Rz(90) takes the child's +x to +z.
        let s = parse_vs_csg("rotate(90, 0, 90) translate([3,0,0]) sphere(1);", 1).unwrap();
        assert!(s.contains(DVec3::new(0.0, 0.0, 3.0)), "{s:?}");
        assert!(!s.contains(DVec3::new(0.0, 3.0, 0.0)));
        // VisibleSim's box is that of the two rotated corners only: a 45°
        // turn of a cube is flat in x (the true box would be ±√2).
        let s = parse_vs_csg("rotate([0,0,45]) cube([2,2,2]);", 1).unwrap();
        let (a, b) = s.bounding_box();
        assert!(a.x.abs() < 1e-12 && b.x.abs() < 1e-12, "{a} {b}");
        assert!((b.y - std::f64::consts::SQRT_2).abs() < 1e-12);
    }

    #[test]
    fn refusals_name_the_files_line() {
        let e = parse_vs_csg("\nunion() {\n polyhedron([0,0,45]);\n}", 10).unwrap_err();
        assert!(
            e.message.contains("CSG line 12") && e.message.contains("polyhedron"),
            "{}",
            e.message
        );
        let e =
            parse_vs_csg("translate([1,0,0]) { cube([1,1,1]); cube([2,2,2]); }", 1).unwrap_err();
        assert!(e.message.contains("next object only"), "{}", e.message);
        let deep = format!(
            "{}cube(1,1,1);{}",
            "union() {".repeat(10_000),
            "}".repeat(10_000)
        );
        assert!(
            parse_vs_csg(&deep, 1)
                .unwrap_err()
                .message
                .contains("nested")
        );
    }
}
