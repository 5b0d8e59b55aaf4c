//! What the parser cannot see: sizes that must be positive, a tool that
//! does not fit the specimen or starts inside it, inclusions outside the
//! specimen, overlapping or cut by its faces, layers that do not add up,
//! a protocol deeper than the specimen, a tool the specimen's kind has no
//! model for. Every error is an [`FeError::InvalidConfig`] naming the field
//! and saying what would be valid.

use std::path::Path;

use super::{
    BlockKinematics, BulkSpec, CylinderKinematics, ElementSpec, Experiment, Inclusion,
    InclusionShape, MeshKinematics, Segment, Specimen, Tool, Value,
};
use crate::mesh::Mesh;
use crate::FeError;

fn bad(field: impl Into<String>, reason: impl Into<String>) -> FeError {
    FeError::InvalidConfig {
        field: field.into(),
        reason: reason.into(),
    }
}

/// A length that must be finite and > 0 (mm).
fn positive(field: &str, v: f64) -> Result<f64, FeError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(bad(field, format!("{v}: expected a length > 0 (mm)")))
    }
}

/// The specimen's geometry as the checks and the builders see it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// An axisymmetric cylinder (the tool on the axis).
    Axisymmetric { radius: f64, height: f64 },
    /// A cylinder in 3D (axis x = y = 0, base z = 0).
    Cylinder3d { radius: f64, height: f64 },
    /// A plane block: x in [0, length], z in [0, height]; `thickness` out
    /// of plane (plane stress) or `None` (plane strain: forces per mm).
    Plane {
        length: f64,
        height: f64,
        thickness: Option<f64>,
        stress: bool,
    },
    /// A 3D block: x and y centred on the top face's centre, z in [0, size[2]].
    Block3d { size: [f64; 3] },
    /// A Gmsh mesh (its geometry is the file's).
    Mesh,
}

impl Shape {
    /// The height (mm), `None` for a Gmsh mesh.
    pub fn height(&self) -> Option<f64> {
        match *self {
            Shape::Axisymmetric { height, .. } | Shape::Cylinder3d { height, .. } => Some(height),
            Shape::Plane { height, .. } => Some(height),
            Shape::Block3d { size } => Some(size[2]),
            Shape::Mesh => None,
        }
    }

    /// The largest radius a tool centred on the top face may have: the
    /// cylinder's radius, half the block's smaller width.
    fn half_width(&self) -> Option<f64> {
        match *self {
            Shape::Axisymmetric { radius, .. } | Shape::Cylinder3d { radius, .. } => Some(radius),
            Shape::Plane { length, .. } => Some(length / 2.0),
            Shape::Block3d { size } => Some(size[0].min(size[1]) / 2.0),
            Shape::Mesh => None,
        }
    }

    fn is_3d(&self) -> bool {
        matches!(self, Shape::Cylinder3d { .. } | Shape::Block3d { .. })
    }
}

/// An inclusion's centre: the horizontal coordinates (none on an
/// axisymmetric cylinder's axis, `[x]` in a plane block, `[x, y]` in 3D)
/// and the depth below the top face (mm).
#[derive(Debug, Clone, PartialEq)]
pub struct Placed {
    pub horizontal: Vec<f64>,
    pub depth: f64,
    pub radius: f64,
}

impl Experiment {
    /// The specimen's geometry, checked: sizes > 0, layers that add up to
    /// the height. The height of a cylinder may be missing (it may come
    /// from a record's metadata): then `Ok(None)`.
    pub fn shape(&self) -> Result<Option<Shape>, FeError> {
        Ok(Some(match &self.specimen {
            Specimen::Cylinder(c) => {
                let radius = positive("specimen.radius", c.radius)?;
                let mut sum = 0.0;
                for (i, l) in c.layers.iter().enumerate() {
                    sum += positive(&format!("specimen.layers[{i}].thickness"), l.thickness)?;
                }
                let height = match c.height {
                    Some(h) => {
                        let h = positive("specimen.height", h)?;
                        if !c.layers.is_empty() && (sum - h).abs() > 1e-9 * h {
                            return Err(bad(
                                "specimen.height",
                                format!(
                                    "{h} mm, but the layers add up to {sum} mm: give the layers' thicknesses summing to the height, or omit the height"
                                ),
                            ));
                        }
                        h
                    }
                    None if !c.layers.is_empty() => sum,
                    None => return Ok(None),
                };
                match c.kinematics {
                    CylinderKinematics::Axisymmetric => Shape::Axisymmetric { radius, height },
                    CylinderKinematics::ThreeD => Shape::Cylinder3d { radius, height },
                }
            }
            Specimen::Block(b) => match b.kinematics {
                BlockKinematics::PlaneStress | BlockKinematics::PlaneStrain => {
                    if b.size.is_some() {
                        return Err(bad(
                            "specimen.size",
                            "a plane block takes `length`, `height` (and `thickness`), not `size`",
                        ));
                    }
                    let stress = b.kinematics == BlockKinematics::PlaneStress;
                    let length = positive(
                        "specimen.length",
                        b.length.ok_or_else(|| {
                            bad(
                                "specimen.length",
                                "missing: the block's length along x (mm)",
                            )
                        })?,
                    )?;
                    let height = positive(
                        "specimen.height",
                        b.height.ok_or_else(|| {
                            bad("specimen.height", "missing: the block's height (mm)")
                        })?,
                    )?;
                    let thickness = match b.thickness {
                        Some(t) => Some(positive("specimen.thickness", t)?),
                        None if stress => {
                            return Err(bad(
                                "specimen.thickness",
                                "missing: a plane-stress block's out-of-plane thickness (mm)",
                            ))
                        }
                        None => None,
                    };
                    Shape::Plane {
                        length,
                        height,
                        thickness,
                        stress,
                    }
                }
                BlockKinematics::ThreeD => {
                    for (f, v) in [
                        ("specimen.length", b.length),
                        ("specimen.height", b.height),
                        ("specimen.thickness", b.thickness),
                    ] {
                        if v.is_some() {
                            return Err(bad(
                                f,
                                "a 3D block takes `size = [x, y, z]` (mm), not length, height or thickness",
                            ));
                        }
                    }
                    let size = b.size.ok_or_else(|| {
                        bad(
                            "specimen.size",
                            "missing: the 3D block's `size = [x, y, z]` (mm)",
                        )
                    })?;
                    for (i, s) in size.iter().enumerate() {
                        positive(&format!("specimen.size[{i}]"), *s)?;
                    }
                    Shape::Block3d { size }
                }
            },
            Specimen::Mesh(_) => Shape::Mesh,
        }))
    }

    /// The inclusions placed in the specimen (centre, depth, radius), each
    /// checked: inside the specimen, clear of its faces and of the others.
    pub fn placed_inclusions(&self) -> Result<Vec<Placed>, FeError> {
        let (list, shape) = match (&self.specimen, self.shape()?) {
            (Specimen::Cylinder(c), Some(s)) => (&c.inclusions, s),
            (Specimen::Block(b), Some(s)) => (&b.inclusions, s),
            (Specimen::Cylinder(c), None) if !c.inclusions.is_empty() => {
                return Err(bad(
                    "specimen.height",
                    "missing: inclusions are placed by depth, so the height is needed",
                ))
            }
            _ => return Ok(Vec::new()),
        };
        let mut placed: Vec<Placed> = Vec::new();
        for (i, inc) in list.iter().enumerate() {
            let p = place(i, inc, &shape)?;
            for (j, q) in placed.iter().enumerate() {
                let d2: f64 = p
                    .horizontal
                    .iter()
                    .zip(&q.horizontal)
                    .map(|(a, b)| (a - b).powi(2))
                    .sum::<f64>()
                    + (p.depth - q.depth).powi(2);
                if d2.sqrt() < p.radius + q.radius {
                    return Err(bad(
                        format!("specimen.inclusions[{i}]"),
                        format!(
                            "overlaps specimen.inclusions[{j}] (centres {:.4} mm apart, radii {} and {} mm): inclusions must be apart",
                            d2.sqrt(),
                            p.radius,
                            q.radius
                        ),
                    ));
                }
            }
            placed.push(p);
        }
        Ok(placed)
    }

    /// The effective height of the specimen (mm): the given height, the
    /// sum of the layers, the block's; `None` when not given (a cylinder
    /// whose height comes from a record) or a Gmsh mesh.
    pub fn height(&self) -> Option<f64> {
        self.shape().ok().flatten().and_then(|s| s.height())
    }

    /// Refuses what the parser cannot see, naming the field: sizes that are
    /// not > 0, layers that do not add up to the height, an inclusion
    /// outside the specimen, cut by its top or base or overlapping another,
    /// a tool larger than the specimen or starting inside it, a protocol
    /// deeper than the specimen, a tool this specimen has no model for, a
    /// mesh element of the wrong dimension, a Gmsh file whose physical
    /// groups name no region, and (through [`Experiment::parameters`])
    /// undeclared or unused materials, unknown laws and parameters, and
    /// a parameter named twice.
    pub fn check(&self) -> Result<(), FeError> {
        self.parameters()?;
        for (name, m) in &self.materials {
            check_material(name, m)?;
        }
        let shape = self.shape()?;
        self.placed_inclusions()?;
        self.check_tool(shape)?;
        self.check_protocol(shape)?;
        self.check_mesh_spec(shape)?;
        if let Specimen::Mesh(m) = &self.specimen {
            self.check_gmsh(m)?;
        }
        Ok(())
    }

    fn check_tool(&self, shape: Option<Shape>) -> Result<(), FeError> {
        let kind = tool_kind(&self.tool);
        // what each specimen can be pressed with
        let on_mesh = matches!(self.specimen, Specimen::Mesh(_));
        match (&self.tool, shape) {
            (Tool::Wheel(_), Some(Shape::Plane { .. })) => {}
            (Tool::Wheel(_), _) => {
                return Err(bad(
                    "tool.shape",
                    "a wheel rolls on a plane block (specimen.shape = \"block\", kinematics = \"plane_stress\" or \"plane_strain\"); on this specimen: sphere, cone, needle, flat_punch or platens",
                ))
            }
            (Tool::Platens(_), Some(Shape::Axisymmetric { .. })) => {}
            (Tool::Platens(_), _) => {
                return Err(bad(
                    "tool.shape",
                    "platens compress an axisymmetric cylinder (specimen.shape = \"cylinder\"); a block or a 3D specimen between platens is not supported",
                ))
            }
            (_, Some(Shape::Plane { .. })) => {
                return Err(bad(
                    "tool.shape",
                    format!(
                        "a {kind} is axisymmetric or 3D; on a plane block the tool is a wheel (shape = \"wheel\")"
                    ),
                ))
            }
            _ => {}
        }
        let half = shape.and_then(|s| s.half_width());
        let larger = |field: &str, r: f64| -> Result<(), FeError> {
            if let Some(h) = half {
                if r >= h {
                    return Err(bad(
                        field,
                        format!(
                            "{r} mm: the {kind} is as large as the specimen (radius or half-width {h} mm); it must be smaller"
                        ),
                    ));
                }
            }
            Ok(())
        };
        let at = match &self.tool {
            Tool::Sphere(t) => {
                larger("tool.radius", positive("tool.radius", t.radius)?)?;
                t.at
            }
            Tool::Cone(t) | Tool::Needle(t) => {
                let needle = matches!(self.tool, Tool::Needle(_));
                if let Some(a) = t.half_angle {
                    if !(a > 0.0 && a < 90.0) {
                        return Err(bad(
                            "tool.half_angle",
                            format!("{a}: expected an angle in degrees, > 0 and < 90"),
                        ));
                    }
                }
                if let Some(r) = t.tip_radius {
                    if needle || r != 0.0 {
                        larger("tool.tip_radius", positive("tool.tip_radius", r)?)?;
                    }
                }
                t.at
            }
            Tool::FlatPunch(t) => {
                let r = positive("tool.radius", t.radius)?;
                larger("tool.radius", r)?;
                if let Some(e) = t.edge_radius {
                    if !(e > 0.0 && e < r) {
                        return Err(bad(
                            "tool.edge_radius",
                            format!(
                                "{e}: expected a radius in mm, > 0 and below the punch radius {r}"
                            ),
                        ));
                    }
                }
                t.at
            }
            Tool::Platens(_) => None,
            Tool::Wheel(t) => {
                let r = positive("tool.radius", t.radius)?;
                larger("tool.radius", r)?;
                if let Some(h) = shape.and_then(|s| s.height()) {
                    if r >= h {
                        return Err(bad(
                            "tool.radius",
                            format!("{r} mm: the wheel is as large as the block's height {h} mm"),
                        ));
                    }
                }
                let mut seen = Vec::new();
                for (i, a) in t.report.iter().enumerate() {
                    if seen.contains(a) {
                        return Err(bad(
                            format!("tool.report[{i}]"),
                            "given twice: report = [\"vertical\"] or [\"vertical\", \"horizontal\"]",
                        ));
                    }
                    seen.push(*a);
                }
                None
            }
        };
        if let Some(at) = at {
            match shape {
                Some(Shape::Block3d { size }) => {
                    for (k, (a, s)) in at.iter().zip(size).enumerate() {
                        if !(a.is_finite() && a.abs() < s / 2.0) {
                            return Err(bad(
                                format!("tool.at[{k}]"),
                                format!(
                                    "{a} mm is outside the top face: x and y are measured from its centre, within +-{} mm",
                                    s / 2.0
                                ),
                            ));
                        }
                    }
                }
                Some(Shape::Cylinder3d { radius, .. }) => {
                    let r = at[0].hypot(at[1]);
                    if !(r < radius) {
                        return Err(bad(
                            "tool.at",
                            format!(
                                "[{}, {}] is outside the top face: within {radius} mm of its centre",
                                at[0], at[1]
                            ),
                        ));
                    }
                }
                _ if on_mesh => {}
                _ => {
                    return Err(bad(
                        "tool.at",
                        "a position on the top face is for a 3D specimen (kinematics = \"3d\"); here the tool is on the axis",
                    ))
                }
            }
        }
        Ok(())
    }

    /// The segments that move the tool: `protocol.segments`, or a wheel's
    /// `tool.path`.
    pub fn segments(&self) -> &[Segment] {
        match &self.tool {
            Tool::Wheel(w) if !w.path.is_empty() => &w.path,
            _ => &self.protocol.segments,
        }
    }

    fn check_protocol(&self, shape: Option<Shape>) -> Result<(), FeError> {
        let p = &self.protocol;
        let wheel = matches!(self.tool, Tool::Wheel(_));
        if let Tool::Wheel(w) = &self.tool {
            if !w.path.is_empty() && !p.segments.is_empty() {
                return Err(bad(
                    "protocol.segments",
                    "the wheel's path is given in tool.path: give it once",
                ));
            }
        }
        let (segments, prefix) = match &self.tool {
            Tool::Wheel(w) if !w.path.is_empty() => (&w.path, "tool.path"),
            _ => (&p.segments, "protocol.segments"),
        };
        if p.from_record.is_some() && !segments.is_empty() {
            return Err(bad(
                prefix,
                "the protocol is taken from the record (protocol.from_record): give segments or a record, not both",
            ));
        }
        if p.samples == Some(0) {
            return Err(bad("protocol.samples", "0: expected samples per ramp >= 1"));
        }
        let height = shape.and_then(|s| s.height());
        let (length, top) = match shape {
            Some(Shape::Plane { length, .. }) => (Some(length), "the block"),
            _ => (None, "the specimen"),
        };
        let mut depth = 0.0;
        let mut timed: Option<(bool, String)> = None;
        for (i, s) in segments.iter().enumerate() {
            let f = |k: &str| format!("{prefix}[{i}].{k}");
            let kinds: Vec<&str> = [
                ("ramp_to", s.ramp_to.is_some()),
                ("unload_to", s.unload_to.is_some()),
                ("hold", s.hold.is_some()),
                ("press_to", s.press_to.is_some()),
                ("roll_to_x", s.roll_to_x.is_some()),
            ]
            .iter()
            .filter(|(_, b)| *b)
            .map(|(k, _)| *k)
            .collect();
            if kinds.len() != 1 {
                return Err(bad(
                    format!("{prefix}[{i}]"),
                    format!(
                        "{}: a segment is one of {{ ramp_to, time }}, {{ hold }}, {{ unload_to, time }}{}",
                        if kinds.is_empty() {
                            "empty".to_string()
                        } else {
                            format!("has {}", kinds.join(" and "))
                        },
                        if wheel {
                            ", { press_to, at_x }, { roll_to_x, time }"
                        } else {
                            ""
                        }
                    ),
                ));
            }
            let kind = kinds[0];
            if !wheel && matches!(kind, "press_to" | "roll_to_x") {
                return Err(bad(
                    f(kind),
                    "a wheel's segment; this tool is driven by ramp_to, hold and unload_to",
                ));
            }
            if s.at_x.is_some() && kind != "press_to" {
                return Err(bad(
                    f("at_x"),
                    "only with press_to: { press_to = 6.0, at_x = 10.0 }",
                ));
            }
            if wheel && i == 0 && kind != "press_to" {
                return Err(bad(
                    f(kind),
                    "the wheel's path starts with { press_to = .., at_x = .. }: where it is pressed into the block",
                ));
            }
            if let Some(t) = s.time {
                if kind == "hold" {
                    return Err(bad(
                        f("time"),
                        "a hold's duration is `hold` (s), not `time`",
                    ));
                }
                if !(t.is_finite() && t > 0.0) {
                    return Err(bad(f("time"), format!("{t}: expected a duration > 0 (s)")));
                }
            }
            if matches!(kind, "ramp_to" | "unload_to" | "press_to") {
                let has = s.time.is_some();
                match &timed {
                    None => timed = Some((has, f("time"))),
                    Some((t, first)) if *t != has => {
                        return Err(bad(
                            f("time"),
                            format!(
                                "{}: either every ramp has a time or none does (see {first})",
                                if has { "given" } else { "missing" }
                            ),
                        ))
                    }
                    _ => {}
                }
            }
            let deep = |field: String, d: f64| -> Result<f64, FeError> {
                if !d.is_finite() || d < 0.0 {
                    return Err(bad(
                        field,
                        format!(
                            "{d}: depths are >= 0 mm from the tool just touching the surface (a negative depth is above it)"
                        ),
                    ));
                }
                if let Some(h) = height {
                    if d >= h {
                        return Err(bad(
                            field,
                            format!("{d} mm is as deep as {top} is high ({h} mm): expected a depth below the height"),
                        ));
                    }
                }
                Ok(d)
            };
            match kind {
                "ramp_to" => depth = deep(f("ramp_to"), s.ramp_to.unwrap_or(0.0))?,
                "press_to" => depth = deep(f("press_to"), s.press_to.unwrap_or(0.0))?,
                "unload_to" => {
                    let u = deep(f("unload_to"), s.unload_to.unwrap_or(0.0))?;
                    if u > depth {
                        return Err(bad(
                            f("unload_to"),
                            format!(
                                "{u} mm is deeper than the tool is ({depth} mm): unloading goes up"
                            ),
                        ));
                    }
                    depth = u;
                }
                "hold" => {
                    let h = s.hold.unwrap_or(0.0);
                    if !(h.is_finite() && h > 0.0) {
                        return Err(bad(f("hold"), format!("{h}: expected a duration > 0 (s)")));
                    }
                    if let Some((false, first)) = &timed {
                        return Err(bad(
                            f("hold"),
                            format!("a hold needs timed ramps: give {first}"),
                        ));
                    }
                }
                _ => {}
            }
            let within = |field: String, x: f64| -> Result<(), FeError> {
                if let Some(l) = length {
                    if !(x.is_finite() && (0.0..=l).contains(&x)) {
                        return Err(bad(
                            field,
                            format!(
                                "{x} mm is outside the block: expected a position in [0, {l}] mm"
                            ),
                        ));
                    }
                }
                Ok(())
            };
            if kind == "press_to" {
                match s.at_x {
                    Some(x) => within(f("at_x"), x)?,
                    None if i == 0 => {
                        return Err(bad(
                            f("at_x"),
                            "missing: where the wheel is pressed (mm along the block)",
                        ))
                    }
                    None => {}
                }
            }
            if let Some(x) = s.roll_to_x {
                within(f("roll_to_x"), x)?;
            }
        }
        Ok(())
    }

    fn check_mesh_spec(&self, shape: Option<Shape>) -> Result<(), FeError> {
        let m = &self.mesh;
        if let Some(a) = m.accuracy {
            if !(a > 0.0 && a < 1.0) {
                return Err(bad(
                    "mesh.accuracy",
                    format!("{a}: expected a relative error, > 0 and < 1 (0.01 is 1 %)"),
                ));
            }
            if m.level.is_some() {
                return Err(bad("mesh.level", "give `accuracy` or `level`, not both"));
            }
        }
        if m.level == Some(0) {
            return Err(bad("mesh.level", "0: levels are 1 (coarse), 2, 3, ..."));
        }
        if let Some(el) = m.element {
            let three_d = match (&self.specimen, shape) {
                (Specimen::Mesh(s), _) => s.kinematics == MeshKinematics::ThreeD,
                (_, Some(s)) => s.is_3d(),
                (Specimen::Cylinder(c), None) => c.kinematics == CylinderKinematics::ThreeD,
                _ => false,
            };
            let is_hex = matches!(el, ElementSpec::Hex8 | ElementSpec::Hex27);
            if is_hex != three_d {
                return Err(bad(
                    "mesh.element",
                    if three_d {
                        "a 3D experiment: hex8 or hex27"
                    } else {
                        "an axisymmetric or plane experiment: quad4 or quad9"
                    },
                ));
            }
        }
        Ok(())
    }

    fn check_gmsh(&self, s: &super::MeshSpecimen) -> Result<(), FeError> {
        let mesh = Mesh::read_gmsh(Path::new(&s.file))?;
        let file = &s.file;
        if mesh.regions.is_empty() {
            return Err(bad(
                "specimen.file",
                format!("{file}: no physical group names a region (a group of the mesh's dimension); name the material regions in Gmsh"),
            ));
        }
        let regions: Vec<&String> = mesh.regions.keys().collect();
        let list = || {
            regions
                .iter()
                .map(|s| s.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        };
        if s.regions.is_empty() {
            for name in self.materials.keys() {
                if !mesh.regions.contains_key(name) {
                    return Err(bad(
                        format!("materials.{name}"),
                        format!(
                            "{file} has no region `{name}` (its regions: {}); map groups to materials with specimen.regions",
                            list()
                        ),
                    ));
                }
            }
        } else {
            for group in s.regions.keys() {
                if !mesh.regions.contains_key(group) {
                    return Err(bad(
                        format!("specimen.regions.{group}"),
                        format!("{file} has no region `{group}`; its regions: {}", list()),
                    ));
                }
            }
        }
        for r in &regions {
            let named = if s.regions.is_empty() {
                self.materials.contains_key(r.as_str())
            } else {
                s.regions.contains_key(r.as_str())
            };
            if !named {
                return Err(bad(
                    "specimen.regions",
                    format!("{file}: region `{r}` has no material; give it one (specimen.regions.{r} = \"MATERIAL\")"),
                ));
            }
        }
        let boundary = |field: &str, g: &str| -> Result<(), FeError> {
            if mesh.facet_sets.contains_key(g) || mesh.node_sets.contains_key(g) {
                Ok(())
            } else {
                let mut sets: Vec<&str> = mesh.facet_sets.keys().map(|s| s.as_str()).collect();
                sets.sort();
                Err(bad(
                    field,
                    format!(
                        "{file} has no boundary group `{g}`; its boundary groups: {}",
                        if sets.is_empty() {
                            "none".into()
                        } else {
                            sets.join(", ")
                        }
                    ),
                ))
            }
        };
        boundary("specimen.support.group", &s.support.group)?;
        boundary("specimen.contact_surface", &s.contact_surface)?;
        let dim_ok = match s.kinematics {
            MeshKinematics::ThreeD => mesh.dim == 3,
            _ => mesh.dim == 2,
        };
        if !dim_ok {
            return Err(bad(
                "specimen.kinematics",
                format!("{file} is a {}D mesh; kinematics = \"3d\" goes with a 3D mesh, the others with a 2D one", mesh.dim),
            ));
        }
        Ok(())
    }
}

fn tool_kind(t: &Tool) -> &'static str {
    match t {
        Tool::Sphere(_) => "sphere",
        Tool::Cone(_) => "cone",
        Tool::Needle(_) => "needle",
        Tool::FlatPunch(_) => "flat punch",
        Tool::Platens(_) => "platen",
        Tool::Wheel(_) => "wheel",
    }
}

/// One inclusion placed and checked against the specimen's faces.
fn place(i: usize, inc: &Inclusion, shape: &Shape) -> Result<Placed, FeError> {
    let f = |k: &str| format!("specimen.inclusions[{i}].{k}");
    let radius = positive(&f("radius"), inc.radius)?;
    let (want, dims, height) = match *shape {
        Shape::Plane { height, .. } => (InclusionShape::Circle, 1, height),
        Shape::Axisymmetric { height, .. } => (InclusionShape::Sphere, 0, height),
        Shape::Cylinder3d { height, .. }
        | Shape::Block3d {
            size: [_, _, height],
        } => (InclusionShape::Sphere, 2, height),
        Shape::Mesh => {
            return Err(bad(
                f("shape"),
                "a Gmsh specimen's inclusions are its regions",
            ))
        }
    };
    if inc.shape != want {
        return Err(bad(
            f("shape"),
            match want {
                InclusionShape::Circle => {
                    "a plane block's inclusions are circles (shape = \"circle\")"
                }
                InclusionShape::Sphere => {
                    "an axisymmetric or 3D specimen's inclusions are spheres (shape = \"sphere\")"
                }
            },
        ));
    }
    let finite = |field: String, v: f64| -> Result<f64, FeError> {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(bad(field, format!("{v}: expected a coordinate in mm")))
        }
    };
    let centre = inc.centre.clone().unwrap_or_default();
    let mut horizontal = Vec::new();
    if dims == 1 {
        match (inc.x, centre.first()) {
            (Some(_), Some(_)) => {
                return Err(bad(f("x"), "give `x` or `centre = [x, z]`, not both"))
            }
            (Some(x), None) => horizontal.push(finite(f("x"), x)?),
            (None, Some(x)) => horizontal.push(finite(f("centre"), *x)?),
            (None, None) => {
                return Err(bad(
                    f("x"),
                    "missing: the centre's position along the block (mm)",
                ))
            }
        }
    } else if inc.x.is_some() {
        return Err(bad(
            f("x"),
            if dims == 0 {
                "an axisymmetric cylinder's inclusions are on the axis: give `depth` only"
            } else {
                "a 3D inclusion's position is `centre = [x, y]` with `depth`, or `centre = [x, y, z]`"
            },
        ));
    } else if dims == 2 {
        if centre.len() < 2 {
            return Err(bad(
                f("centre"),
                "missing: `centre = [x, y]` with `depth`, or `centre = [x, y, z]` (x and y from the top face's centre, z up from the base)",
            ));
        }
        horizontal.push(finite(f("centre"), centre[0])?);
        horizontal.push(finite(f("centre"), centre[1])?);
    } else if centre.len() > 1 && centre[0] != 0.0 {
        return Err(bad(
            f("centre"),
            "an axisymmetric cylinder's inclusions are on the axis (r = 0); off the axis needs kinematics = \"3d\"",
        ));
    }
    // the vertical coordinate: `depth`, or the centre's last one (z up
    // from the base); on the axis `centre = [0, z]`
    let full = dims + 1;
    let from_centre = if dims == 0 {
        (centre.len() == 2).then(|| centre[1])
    } else {
        (centre.len() == full).then(|| centre[dims])
    };
    if centre.len() > full
        || (dims > 0 && !centre.is_empty() && centre.len() != dims && centre.len() != full)
    {
        return Err(bad(
            f("centre"),
            format!(
                "{} coordinates: expected {}",
                centre.len(),
                match dims {
                    0 => "none (give `depth`) or [0, z]",
                    1 => "[x, z], or `x` with `depth`",
                    _ => "[x, y, z], or [x, y] with `depth`",
                }
            ),
        ));
    }
    let depth = match (inc.depth, from_centre) {
        (Some(_), Some(_)) => {
            return Err(bad(
                f("depth"),
                "give `depth` or the centre's vertical coordinate, not both",
            ))
        }
        (Some(d), None) => finite(f("depth"), d)?,
        (None, Some(z)) => height - finite(f("centre"), z)?,
        (None, None) => {
            return Err(bad(
                f("depth"),
                "missing: the depth of the centre below the top face (mm)",
            ))
        }
    };
    if depth - radius <= 0.0 {
        return Err(bad(
            f("depth"),
            format!(
                "{depth} mm with radius {radius} mm: the inclusion is cut by the top surface (or above it); expected a depth > {radius} mm"
            ),
        ));
    }
    if depth + radius >= height {
        return Err(bad(
            f("depth"),
            format!(
                "{depth} mm with radius {radius} mm: the inclusion is cut by the base (height {height} mm) or below it; expected a depth < {} mm",
                height - radius
            ),
        ));
    }
    let outside = |field: String, what: String| -> FeError {
        bad(
            field,
            format!("the inclusion (radius {radius} mm) is outside the specimen or cut by its side: {what}"),
        )
    };
    match *shape {
        Shape::Axisymmetric { radius: r, .. } => {
            if radius >= r {
                return Err(outside(
                    f("radius"),
                    format!("the cylinder's radius is {r} mm"),
                ));
            }
        }
        Shape::Cylinder3d { radius: r, .. } => {
            let rc = horizontal[0].hypot(horizontal[1]);
            if rc + radius >= r {
                return Err(outside(
                    f("centre"),
                    format!("its centre is {rc} mm from the axis of a cylinder of radius {r} mm"),
                ));
            }
        }
        Shape::Plane { length, .. } => {
            let x = horizontal[0];
            if x - radius <= 0.0 || x + radius >= length {
                let field = if inc.x.is_some() { f("x") } else { f("centre") };
                return Err(outside(
                    field,
                    format!("x = {x} mm, the block spans [0, {length}] mm"),
                ));
            }
        }
        Shape::Block3d { size } => {
            for k in 0..2 {
                let half = size[k] / 2.0;
                if horizontal[k].abs() + radius >= half {
                    return Err(outside(
                        f("centre"),
                        format!(
                            "{} = {} mm, the block spans +-{half} mm from the top face's centre",
                            ["x", "y"][k],
                            horizontal[k]
                        ),
                    ));
                }
            }
        }
        Shape::Mesh => {}
    }
    Ok(Placed {
        horizontal,
        depth,
        radius,
    })
}

/// A material's numbers that [`Experiment::parameters`] does not see: the
/// bulk treatment and fixed Prony terms.
fn check_material(name: &str, m: &super::MaterialSpec) -> Result<(), FeError> {
    match &m.bulk {
        Some(BulkSpec::Ratio(k)) if !(k.is_finite() && *k > 0.0) => {
            return Err(bad(
                format!("materials.{name}.bulk"),
                format!("{k}: expected \"exact\" or a bulk-to-shear ratio K / mu0 > 0 (e.g. 1000)"),
            ))
        }
        Some(BulkSpec::Keyword(k)) if k != "exact" => {
            return Err(bad(
                format!("materials.{name}.bulk"),
                format!(
                    "`{k}`: expected \"exact\" or a bulk-to-shear ratio K / mu0 > 0 (e.g. 1000)"
                ),
            ))
        }
        _ => {}
    }
    let mut sum = 0.0;
    for (i, t) in m.prony.iter().enumerate() {
        let start = |v: &Value| match v {
            Value::Fixed(x) => Some(*x),
            Value::Param(p) => Some(p.start),
            Value::Keyword(_) => None,
        };
        let g = start(&t.g).ok_or_else(|| {
            bad(
                format!("materials.{name}.prony[{i}].g"),
                "expected a number in [0, 1) or { start = .. }",
            )
        })?;
        let tau = start(&t.tau).ok_or_else(|| {
            bad(
                format!("materials.{name}.prony[{i}].tau"),
                "expected a time > 0 (s) or { start = .. }",
            )
        })?;
        if !(g.is_finite() && (0.0..1.0).contains(&g)) {
            return Err(bad(
                format!("materials.{name}.prony[{i}].g"),
                format!("{g}: expected a weight in [0, 1)"),
            ));
        }
        if !(tau.is_finite() && tau > 0.0) {
            return Err(bad(
                format!("materials.{name}.prony[{i}].tau"),
                format!("{tau}: expected a time > 0 (s)"),
            ));
        }
        sum += g;
    }
    if sum >= 1.0 {
        return Err(bad(
            format!("materials.{name}.prony"),
            format!("the weights g add up to {sum}: they must add up to less than 1"),
        ));
    }
    Ok(())
}
