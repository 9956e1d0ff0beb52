//! A small OpenSCAD-like CSG language for goal shapes (seed 000 §5.2.1).
//!
//! Supported: `cube(size | [x, y, z], center = bool)`, `sphere(r | radius
//! = r)`, `cylinder(h | height = …, r | radius = …, center = bool)`,
//! `translate([x, y, z]) object`, `scale([x, y, z]) object` (positive
//! factors), `rotate([a, b, c]) object` (degrees, OpenSCAD's order: about x
//! by a, then y by b, then z by c), `union() { … }`, `difference() { … }`,
//! `intersection() { … }`, assignments `name = expr;`, arithmetic
//! (`+ - * /`, parentheses, `sqrt(…)`) and `//` comments. Lengths are in
//! units of the lattice spacing d; z is up. Anything else is refused with
//! an error naming the line — a shape is never silently approximated.

use super::csg_text::{Cursor, Tok, Tokens, lex};
use super::shape::{Shape, Skew};
use crate::error::InputError;
use glam::DVec3;
use std::collections::HashMap;

/// How far outside a solid a cell centre may lie and still be a cell of
/// the shape, in units of d. Cell centres of round shapes fall within
/// thousandths of d of the boundary (a dome of radius 10 has a branch cell
/// at 10.0037): membership must not hinge on rounding. 0.05 d (0.18 mm
/// for 3.6 mm catoms) is well under any dimension a shape is drawn to.
pub const MEMBERSHIP_TOL: f64 = 0.05;

/// A CSG solid.
#[derive(Clone, Debug, PartialEq)]
pub enum Node {
    Cube {
        size: DVec3,
        center: bool,
    },
    Sphere {
        r: f64,
    },
    Cylinder {
        h: f64,
        r: f64,
        center: bool,
    },
    Translate {
        v: DVec3,
        child: Box<Node>,
    },
    /// Scaled by positive factors along x, y, z.
    Scale {
        s: DVec3,
        child: Box<Node>,
    },
    /// Rotated by `r` (child frame → world), with its inverse kept.
    Rotate {
        r: glam::DMat3,
        child: Box<Node>,
    },
    Union(Vec<Node>),
    Difference(Vec<Node>),
    Intersection(Vec<Node>),
}

impl Node {
    /// Whether `p` lies in the solid grown by [`MEMBERSHIP_TOL`] (the
    /// subtracted parts of a difference shrunk by it).
    pub fn contains(&self, p: DVec3) -> bool {
        self.contains_within(p, MEMBERSHIP_TOL)
    }

    /// Whether `p` lies in the solid offset outwards by `tol` (inwards
    /// when `tol < 0`).
    pub fn contains_within(&self, p: DVec3, tol: f64) -> bool {
        match self {
            Node::Cube { size, center } => {
                let lo = if *center { -*size / 2.0 } else { DVec3::ZERO };
                let hi = lo + *size;
                p.cmpge(lo - tol).all() && p.cmple(hi + tol).all()
            }
            Node::Sphere { r } => p.length() <= r + tol,
            Node::Cylinder { h, r, center } => {
                let z0 = if *center { -h / 2.0 } else { 0.0 };
                p.z >= z0 - tol && p.z <= z0 + h + tol && (p.x * p.x + p.y * p.y).sqrt() <= r + tol
            }
            Node::Translate { v, child } => child.contains_within(p - *v, tol),
            // The child's offset divided by the smallest factor: the scaled
            // solid is offset by at least `tol` in every direction (by up
            // to `tol·max/min` along the most stretched axis).
            Node::Scale { s, child } => child.contains_within(p / *s, tol / s.min_element()),
            Node::Rotate { r, child } => child.contains_within(r.transpose() * p, tol),
            Node::Union(c) => c.iter().any(|n| n.contains_within(p, tol)),
            Node::Difference(c) => {
                c.first().is_some_and(|f| f.contains_within(p, tol))
                    && !c[1..].iter().any(|n| n.contains_within(p, -tol))
            }
            Node::Intersection(c) => !c.is_empty() && c.iter().all(|n| n.contains_within(p, tol)),
        }
    }

    /// Axis-aligned bounds (world, units of d).
    pub fn bounds(&self) -> (DVec3, DVec3) {
        match self {
            Node::Cube { size, center } => {
                let lo = if *center { -*size / 2.0 } else { DVec3::ZERO };
                (lo, lo + *size)
            }
            Node::Sphere { r } => (DVec3::splat(-r), DVec3::splat(*r)),
            Node::Cylinder { h, r, center } => {
                let z0 = if *center { -h / 2.0 } else { 0.0 };
                (DVec3::new(-r, -r, z0), DVec3::new(*r, *r, z0 + h))
            }
            Node::Translate { v, child } => {
                let (a, b) = child.bounds();
                (a + *v, b + *v)
            }
            Node::Scale { s, child } => {
                let (a, b) = child.bounds();
                (a * *s, b * *s)
            }
            Node::Rotate { r, child } => {
                // The box of the rotated child's box: its eight corners.
                let (a, b) = child.bounds();
                (0..8)
                    .map(|k| {
                        let c = DVec3::new(
                            if k & 1 == 0 { a.x } else { b.x },
                            if k & 2 == 0 { a.y } else { b.y },
                            if k & 4 == 0 { a.z } else { b.z },
                        );
                        *r * c
                    })
                    .fold(
                        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
                        |(lo, hi), c| (lo.min(c), hi.max(c)),
                    )
            }
            Node::Union(c) => c
                .iter()
                .map(Node::bounds)
                .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)))
                .unwrap_or_default(),
            Node::Difference(c) => c.first().map(Node::bounds).unwrap_or_default(),
            Node::Intersection(c) => c
                .iter()
                .map(Node::bounds)
                .reduce(|(a, b), (c, d)| (a.max(c), b.min(d)))
                .unwrap_or_default(),
        }
    }
}

/// A parsed CSG file as a goal shape.
#[derive(Clone, Debug)]
pub struct CsgShape {
    pub name: String,
    pub root: Node,
}

impl Shape for CsgShape {
    fn contains(&self, c: Skew) -> bool {
        self.root.contains(c.world())
    }
    fn describe(&self) -> String {
        format!("CSG shape '{}'", self.name)
    }
}

impl CsgShape {
    pub fn load(path: &std::path::Path) -> Result<CsgShape, InputError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| InputError::new(format!("cannot read CSG file: {e}")).in_file(path))?;
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        CsgShape::parse(&name, &text).map_err(|e| e.in_file(path))
    }

    pub fn parse(name: &str, text: &str) -> Result<CsgShape, InputError> {
        let mut p = Parser {
            t: Tokens::new(lex(text)?),
            vars: HashMap::new(),
        };
        let mut nodes = Vec::new();
        while !p.t.at_end() {
            if let Some(n) = p.statement()? {
                nodes.push(n);
            }
        }
        if nodes.is_empty() {
            return Err(InputError::new("the CSG file defines no solid"));
        }
        let root = if nodes.len() == 1 {
            nodes.pop().unwrap()
        } else {
            Node::Union(nodes)
        };
        Ok(CsgShape {
            name: name.to_string(),
            root,
        })
    }

    /// Skewed-grid bounds covering the solid.
    pub fn skew_bounds(&self) -> (Skew, Skew) {
        // Clamped far beyond any buildable extent, so that a shape of
        // absurd size reaches the scaffold's size check instead of
        // overflowing here.
        let cell = |v: f64| v.clamp(-1e8, 1e8) as i32;
        let (lo, hi) = self.root.bounds();
        let s2 = std::f64::consts::SQRT_2;
        let z0 = cell((lo.z * s2).floor()) - 1;
        let z1 = cell((hi.z * s2).ceil()) + 1;
        let zmax = z1.max(z0).max(0) as f64;
        let zmin = z0.min(0) as f64;
        (
            Skew::new(
                cell((lo.x - zmax / 2.0).floor()) - 1,
                cell((lo.y - zmax / 2.0).floor()) - 1,
                z0,
            ),
            Skew::new(
                cell((hi.x - zmin / 2.0).ceil()) + 1,
                cell((hi.y - zmin / 2.0).ceil()) + 1,
                z1,
            ),
        )
    }
}

#[derive(Clone, Debug)]
enum Val {
    Num(f64),
    Vec3(DVec3),
    Bool(bool),
}

struct Parser {
    /// Tokens, position, and nesting of objects and parentheses (see
    /// [`MAX_DEPTH`]).
    t: Tokens,
    vars: HashMap<String, f64>,
}

/// Deepest nesting of objects or parenthesised expressions read: the
/// parser and the solid's membership test recurse, so a file nested
/// thousands of levels deep would overflow the stack (a crash, exit 134);
/// it is refused with its position instead. No hand-written shape comes
/// near 100 levels.
pub const MAX_DEPTH: usize = 100;

impl Cursor for Parser {
    fn tokens(&self) -> &Tokens {
        &self.t
    }
    fn tokens_mut(&mut self) -> &mut Tokens {
        &mut self.t
    }
    fn max_depth(&self) -> usize {
        MAX_DEPTH
    }
    fn err(&self, msg: impl std::fmt::Display) -> InputError {
        let (line, col) = self.here().unwrap_or((0, 0));
        InputError::new(format!("line {line}, column {col}: {msg}"))
    }
    fn constant(&self, name: &str) -> Option<f64> {
        self.vars.get(name).copied()
    }
}

impl Parser {
    fn statement(&mut self) -> Result<Option<Node>, InputError> {
        if self.eat(';') {
            return Ok(None);
        }
        if let (Some(Tok::Id(name)), Some((Tok::Sym('='), _, _))) =
            (self.peek().cloned(), self.t.toks.get(self.t.pos + 1))
        {
            self.t.pos += 2;
            let v = self.expr()?;
            self.expect(';')?;
            self.vars.insert(name, v);
            return Ok(None);
        }
        self.object().map(Some)
    }

    fn object(&mut self) -> Result<Node, InputError> {
        self.deeper()?;
        let node = self.object_inner();
        self.t.depth -= 1;
        node
    }

    fn object_inner(&mut self) -> Result<Node, InputError> {
        let Some(Tok::Id(name)) = self.next_tok() else {
            self.t.pos -= 1;
            return Err(self.err("expected a CSG object"));
        };
        let args = self.checked_args(&name)?;
        let num = |k: &str, pos: usize| -> Option<f64> {
            args.iter()
                .find(|(n, _)| n.as_deref() == Some(k))
                .or_else(|| args.iter().filter(|(n, _)| n.is_none()).nth(pos))
                .and_then(|(_, v)| match v {
                    Val::Num(x) => Some(*x),
                    _ => None,
                })
        };
        let center = args
            .iter()
            .any(|(n, v)| n.as_deref() == Some("center") && matches!(v, Val::Bool(true)));
        let node = match name.as_str() {
            "cube" => {
                let size = match args.iter().find(|(n, _)| n.is_none() || n.as_deref() == Some("size")) {
                    Some((_, Val::Vec3(v))) => *v,
                    Some((_, Val::Num(s))) => DVec3::splat(*s),
                    _ => return Err(self.err("cube needs a size")),
                };
                self.expect(';')?;
                Node::Cube { size, center }
            }
            "sphere" => {
                let r = num("r", 0)
                    .or_else(|| num("radius", 0))
                    .or_else(|| num("d", 99).map(|d| d / 2.0))
                    .ok_or_else(|| self.err("sphere needs a radius"))?;
                self.expect(';')?;
                Node::Sphere { r }
            }
            "cylinder" => {
                if args.iter().any(|(n, _)| matches!(n.as_deref(), Some("r1" | "r2" | "d1" | "d2"))) {
                    return Err(self.err("cones (r1 / r2) are not supported: cylinder takes one radius"));
                }
                let h = num("h", 0).or_else(|| num("height", 0)).ok_or_else(|| self.err("cylinder needs a height"))?;
                let r = num("r", 1).or_else(|| num("radius", 1)).ok_or_else(|| self.err("cylinder needs a radius"))?;
                self.expect(';')?;
                Node::Cylinder { h, r, center }
            }
            "translate" => {
                let v = match args.first() {
                    Some((_, Val::Vec3(v))) => *v,
                    _ => return Err(self.err("translate needs a vector [x, y, z]")),
                };
                let child = self.block()?;
                Node::Translate { v, child: Box::new(child) }
            }
            "scale" => {
                let s = match args.first() {
                    Some((_, Val::Vec3(v))) if v.is_finite() && v.cmpgt(DVec3::ZERO).all() => *v,
                    Some((_, Val::Num(k))) if k.is_finite() && *k > 0.0 => DVec3::splat(*k),
                    _ => return Err(self.err("scale needs positive factors [x, y, z]")),
                };
                let child = self.block()?;
                Node::Scale { s, child: Box::new(child) }
            }
            "rotate" => {
                let a = match args.first() {
                    Some((_, Val::Vec3(v))) if v.is_finite() => *v,
                    _ => return Err(self.err("rotate needs angles [x, y, z] in degrees")),
                };
                let r = glam::DMat3::from_rotation_z(a.z.to_radians())
                    * glam::DMat3::from_rotation_y(a.y.to_radians())
                    * glam::DMat3::from_rotation_x(a.x.to_radians());
                let child = self.block()?;
                Node::Rotate { r, child: Box::new(child) }
            }
            "union" | "difference" | "intersection" => {
                let children = self.children()?;
                match name.as_str() {
                    "union" => Node::Union(children),
                    "difference" => Node::Difference(children),
                    _ => Node::Intersection(children),
                }
            }
            other => {
                return Err(self.err(format!(
                    "unsupported CSG operation '{other}' (supported: cube, sphere, cylinder, translate, \
                     scale, rotate, union, difference, intersection)"
                )))
            }
        };
        Ok(node)
    }

    /// The arguments of `object`, refusing what this dialect does not
    /// read — unknown names, extra positional arguments and positional
    /// booleans — with their position. OpenSCAD and VisibleSim read
    /// `cube([..], true)` as centred, `cube(20, 10, 2.1, true)` is no
    /// cube of this dialect, and `cylinder(20, 30, 0)` is an OpenSCAD cone:
    /// none of them may pass as something else.
    fn checked_args(&mut self, object: &str) -> Result<Vec<(Option<String>, Val)>, InputError> {
        let args = self.args_at()?;
        let (named, positional): (&[&str], usize) = match object {
            "cube" => (&["size", "center"], 1),
            "sphere" => (&["r", "radius", "d"], 1),
            "cylinder" => (
                &[
                    "h", "height", "r", "radius", "center", "r1", "r2", "d1", "d2",
                ],
                2,
            ),
            "translate" | "scale" | "rotate" => (&[], 1),
            "union" | "difference" | "intersection" => (&[], 0),
            _ => return Ok(args.into_iter().map(|(n, v, _)| (n, v)).collect()),
        };
        let mut seen = 0;
        let end = self.t.pos;
        for (n, v, at) in &args {
            self.t.pos = *at;
            match n {
                None if matches!(v, Val::Bool(_)) => {
                    return Err(self.err(format!(
                        "a positional true/false in {object}(…) is not read in this dialect \
                         (OpenSCAD and VisibleSim take it as the centre flag): write center = true \
                         or center = false"
                    )));
                }
                None => {
                    seen += 1;
                    if seen > positional {
                        let what = if object == "cylinder" && seen == 3 {
                            " (OpenSCAD reads a third number as r2: a cone)".to_string()
                        } else {
                            String::new()
                        };
                        return Err(self.err(format!(
                            "{object} takes at most {positional} positional argument(s){what}; \
                             name the others"
                        )));
                    }
                }
                Some(k) if !named.contains(&k.as_str()) => {
                    return Err(self.err(format!(
                        "{object} has no argument '{k}' (known: {})",
                        if named.is_empty() {
                            "none named".to_string()
                        } else {
                            named.join(", ")
                        }
                    )));
                }
                Some(k) if k == "center" && !matches!(v, Val::Bool(_)) => {
                    return Err(self.err("center must be true or false"));
                }
                Some(_) => {}
            }
        }
        self.t.pos = end;
        Ok(args.into_iter().map(|(n, v, _)| (n, v)).collect())
    }

    fn block(&mut self) -> Result<Node, InputError> {
        if self.peek() == Some(&Tok::Sym('{')) {
            let mut c = self.children()?;
            Ok(if c.len() == 1 {
                c.pop().unwrap()
            } else {
                Node::Union(c)
            })
        } else {
            self.object()
        }
    }

    fn children(&mut self) -> Result<Vec<Node>, InputError> {
        self.expect('{')?;
        let mut out = Vec::new();
        while !self.eat('}') {
            if self.peek().is_none() {
                return Err(self.err("missing '}'"));
            }
            if let Some(n) = self.statement()? {
                out.push(n);
            }
        }
        Ok(out)
    }

    /// The arguments with the token index each starts at (for errors).
    fn args_at(&mut self) -> Result<Vec<(Option<String>, Val, usize)>, InputError> {
        self.expect('(')?;
        let mut out = Vec::new();
        if self.eat(')') {
            return Ok(out);
        }
        loop {
            let start = self.t.pos;
            let name = match (self.peek().cloned(), self.t.toks.get(self.t.pos + 1)) {
                (Some(Tok::Id(n)), Some((Tok::Sym('='), _, _))) => {
                    self.t.pos += 2;
                    Some(n)
                }
                _ => None,
            };
            let v = if self.eat('[') {
                let x = self.expr()?;
                self.expect(',')?;
                let y = self.expr()?;
                self.expect(',')?;
                let z = self.expr()?;
                self.expect(']')?;
                Val::Vec3(DVec3::new(x, y, z))
            } else if self.peek() == Some(&Tok::Id("true".into())) {
                self.t.pos += 1;
                Val::Bool(true)
            } else if self.peek() == Some(&Tok::Id("false".into())) {
                self.t.pos += 1;
                Val::Bool(false)
            } else {
                Val::Num(self.expr()?)
            };
            out.push((name, v, start));
            if self.eat(')') {
                return Ok(out);
            }
            self.expect(',')?;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_papers_canonical_definitions() {
        let s = CsgShape::parse(
            "t",
            "d = 4; b = 6; D = sqrt(2)/2*d;\n\
             translate([d*b/2, d*b/2, D*b/2]) cube([d*b, d*b, D*b], center=true);",
        )
        .unwrap();
        assert!(s.root.contains(DVec3::new(0.0, 0.0, 0.0)));
        assert!(s.root.contains(DVec3::new(24.0, 24.0, 16.9)));
        assert!(!s.root.contains(DVec3::new(24.5, 1.0, 1.0)));
        let h = CsgShape::parse(
            "h",
            "difference() { sphere(r=5); translate([0,0,-5]) cube([10,10,5]); }",
        )
        .unwrap();
        assert!(h.root.contains(DVec3::new(1.0, 1.0, 1.0)));
        assert!(!h.root.contains(DVec3::new(1.0, 1.0, -1.0)));
        assert!(h.root.contains(DVec3::new(-1.0, -1.0, -1.0)));
    }

    /// The domed cube's knife edge: a branch cell 0.0037 d outside a dome
    /// of radius 10 is a cell of the shape; 0.1 d outside is not. A
    /// subtracted solid is shrunk by the tolerance, so a cell 0.01 d inside
    /// a hole's wall is kept, and one 0.1 d inside it is removed.
    #[test]
    fn membership_has_a_stated_tolerance_of_a_twentieth_of_d() {
        assert_eq!(MEMBERSHIP_TOL, 0.05);
        let dome = Node::Sphere { r: 10.0 };
        assert!(dome.contains(DVec3::new(10.0037, 0.0, 0.0)));
        assert!(!dome.contains(DVec3::new(10.1, 0.0, 0.0)));
        let holed = Node::Difference(vec![
            Node::Cube {
                size: DVec3::splat(10.0),
                center: false,
            },
            Node::Translate {
                v: DVec3::new(5.0, 5.0, 0.0),
                child: Box::new(Node::Cylinder {
                    h: 10.0,
                    r: 2.0,
                    center: false,
                }),
            },
        ]);
        assert!(holed.contains(DVec3::new(5.0 + 1.99, 5.0, 1.0)));
        assert!(!holed.contains(DVec3::new(5.0 + 1.9, 5.0, 1.0)));
        assert!(holed.contains(DVec3::new(10.03, 1.0, 1.0)));
        assert!(!holed.contains(DVec3::new(f64::NAN, 1.0, 1.0)));
    }

    #[test]
    fn what_this_dialect_does_not_read_is_refused_with_line_and_column() {
        let cases = [
            (
                "cube([12, 42, 13.5], true);",
                "line 1, column 22",
                "positional true",
            ),
            (
                "\ncube(20, 10, 2.1, true);",
                "line 2, column 10",
                "at most 1 positional",
            ),
            ("cylinder(20, 30, 0);", "line 1, column 18", "a cone"),
            (
                "sphere(r = 3, $fn = 40);",
                "line 1, column 15",
                "no argument '$fn'",
            ),
            ("cube(3, center = 1);", "line 1, column 9", "center must be"),
            (
                "union(3) { cube(3); }",
                "line 1, column 7",
                "union takes at most 0",
            ),
        ];
        for (text, at, what) in cases {
            let e = CsgShape::parse("t", text).unwrap_err();
            assert!(
                e.message.contains(at) && e.message.contains(what),
                "{text}: {}",
                e.message
            );
        }
        // Named arguments still read as before.
        let c = CsgShape::parse("t", "cylinder(h = 2, r = 3, center = true);").unwrap();
        assert!(c.root.contains(DVec3::new(2.9, 0.0, -0.9)));
    }

    /// 10,000 nested `union()`s (or parentheses, or minus signs) used to
    /// overflow the stack; any depth is now read or refused as input.
    #[test]
    fn any_nesting_depth_is_read_or_refused_without_a_crash() {
        for n in [10, MAX_DEPTH - 1] {
            let text = format!("{}cube(1);{}", "union() {".repeat(n), "}".repeat(n));
            assert!(CsgShape::parse("t", &text).is_ok(), "{n}");
        }
        let deep = [
            format!(
                "{}cube(1);{}",
                "union() {".repeat(10_000),
                "}".repeat(10_000)
            ),
            format!("cube({}1{});", "(".repeat(10_000), ")".repeat(10_000)),
            format!("cube({}1);", "-".repeat(10_000)),
            format!("{}cube(1);", "translate([0,0,0]) ".repeat(10_000)),
        ];
        for text in deep {
            let e = CsgShape::parse("t", &text).unwrap_err();
            assert!(e.message.contains("nested more than"), "{}", e.message);
        }
    }

    #[test]
    fn unsupported_operations_are_named_with_their_line() {
        let e = CsgShape::parse("r", "cube(3);\nmirror([1,0,0]) cube(2);").unwrap_err();
        assert!(
            e.message.contains("line 2, column 1") && e.message.contains("mirror"),
            "{}",
            e.message
        );
        let e = CsgShape::parse("c", "cylinder(h=3, r1=2, r2=1);").unwrap_err();
        assert!(e.message.contains("cones"), "{}", e.message);
    }

    #[test]
    fn rotate_turns_a_cylinder_onto_y_and_scale_stretches_each_axis() {
        // OpenSCAD: rotate([90, 0, 0]) takes +z to −y.
        let c = CsgShape::parse(
            "r",
            "rotate([90, 0, 0]) cylinder(h = 10, r = 1, center = true);",
        )
        .unwrap();
        assert!(c.root.contains(DVec3::new(0.0, 4.0, 0.0)));
        assert!(!c.root.contains(DVec3::new(0.0, 0.0, 4.0)));
        let (lo, hi) = c.root.bounds();
        assert!(
            (lo.y + 5.0).abs() < 1e-12 && (hi.z - 1.0).abs() < 1e-12,
            "{lo} {hi}"
        );
        let e = CsgShape::parse("s", "scale([2, 1, 0.5]) sphere(1);").unwrap();
        assert!(e.root.contains(DVec3::new(1.9, 0.0, 0.0)));
        assert!(!e.root.contains(DVec3::new(0.0, 1.5, 0.0)));
        assert!(!e.root.contains(DVec3::new(0.0, 0.0, 0.7)));
        for bad in [
            "scale([2, 0, 1]) cube(1);",
            "scale([2, -1, 1]) cube(1);",
            "rotate(45) cube(1);",
        ] {
            assert!(CsgShape::parse("b", bad).is_err(), "{bad}");
        }
    }
}
