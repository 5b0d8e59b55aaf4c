//! Reader for Gmsh MSH 4.1 ASCII files.
//!
//! Source: Gmsh reference manual, section "MSH file format" (version 4.1).
//! Sections read: `$MeshFormat` (must be `4.1 0 <data-size>`, i.e. ASCII),
//! `$PhysicalNames`, `$Entities` (the physical tags of each geometric
//! entity), `$Nodes` and `$Elements`; any other section is skipped up to its
//! `$End...` line. Partitioned files (`$PartitionedEntities`) are refused.
//!
//! Conventions of the resulting [`Mesh`]:
//!
//! * Nodes are numbered `0..n` in the order they appear in `$Nodes` (Gmsh
//!   tags may be sparse); coordinates are kept as written. A 2D mesh must lie
//!   in the plane `z = 0`.
//! * Element types: 1 (2-node line), 8 (3-node line), 3 (4-node
//!   quadrilateral), 10 (9-node quadrilateral), 5 (8-node hexahedron) and 15
//!   (point). Gmsh's node order is the crate's, so connectivity is copied.
//!   The mesh dimension is the highest element dimension present (2 or 3);
//!   the cells of that dimension must all be of one type, in file order.
//! * Physical groups of the mesh dimension become regions, named by their
//!   physical name or `physical_<tag>`. Without any such group every cell is
//!   in region `body`; with some, cells of untagged entities go to region
//!   `unassigned` (Gmsh writes those only with `Mesh.SaveAll = 1`).
//! * Physical groups one dimension lower become facet sets (of the cell's
//!   facet type, in file order) and a node set of the same name; groups of
//!   lower dimension (points, and curves in 3D) become node sets. Node sets
//!   are sorted and free of repeats.
//! * Cells are checked for inversion: a corner Jacobian determinant `<= 0`
//!   in 2D (cells must turn counter-clockwise, i.e. the surface normal is
//!   +z), `< 0` at a hexahedron corner.
//!
//! Errors are [`FeError::MeshFile`] with the file name and the 1-based line;
//! nothing panics on bad input.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::Path;

use super::jacobian::corner_jacobians;
use super::{CellType, FacetSet, Mesh};
use crate::FeError;

/// An element type the reader accepts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Point,
    Cell(CellType),
}

impl Kind {
    fn from_code(code: i64) -> Option<Kind> {
        Some(match code {
            1 => Kind::Cell(CellType::Line2),
            8 => Kind::Cell(CellType::Line3),
            3 => Kind::Cell(CellType::Quad4),
            10 => Kind::Cell(CellType::Quad9),
            5 => Kind::Cell(CellType::Hex8),
            15 => Kind::Point,
            _ => return None,
        })
    }
    fn name(self) -> String {
        match self {
            Kind::Point => "Point".into(),
            Kind::Cell(t) => format!("{t:?}"),
        }
    }
    fn nodes(self) -> usize {
        match self {
            Kind::Point => 1,
            Kind::Cell(t) => t.nodes(),
        }
    }
    fn dim(self) -> usize {
        match self {
            Kind::Point => 0,
            Kind::Cell(t) => t.dim(),
        }
    }
}

/// One `$Elements` entity block.
struct Block {
    dim: usize,
    entity: i64,
    kind: Kind,
    /// Line of the block header.
    line: usize,
    /// Node indices, `kind.nodes()` per element.
    nodes: Vec<usize>,
    /// Line of each element.
    lines: Vec<usize>,
}

struct Token<'a> {
    text: &'a str,
    line: usize,
}

/// Whitespace-separated tokens with their line numbers, read section by
/// section.
struct Reader<'a> {
    file: &'a str,
    lines: Vec<&'a str>,
    tokens: Vec<Token<'a>>,
    pos: usize,
    /// The section being read (for "truncated" messages).
    section: String,
}

impl<'a> Reader<'a> {
    fn new(text: &'a str, file: &'a str) -> Self {
        let lines: Vec<&str> = text.lines().collect();
        let tokens = lines
            .iter()
            .enumerate()
            .flat_map(|(i, l)| {
                l.split_whitespace().map(move |t| Token {
                    text: t,
                    line: i + 1,
                })
            })
            .collect();
        Reader {
            file,
            lines,
            tokens,
            pos: 0,
            section: String::new(),
        }
    }

    fn err(&self, line: usize, reason: impl Into<String>) -> FeError {
        FeError::MeshFile {
            file: self.file.into(),
            line,
            reason: reason.into(),
        }
    }

    fn last_line(&self) -> usize {
        self.lines.len()
    }

    /// The next token of the current section; a `$` token or the end of the
    /// file means the section is truncated.
    fn token(&mut self, what: &str) -> Result<&'a str, FeError> {
        match self.tokens.get(self.pos) {
            None => Err(self.err(
                self.last_line(),
                format!(
                    "truncated {}: end of file while reading {what}",
                    self.section
                ),
            )),
            Some(t) if t.text.starts_with('$') => Err(self.err(
                t.line,
                format!(
                    "truncated {}: found `{}` while reading {what}",
                    self.section, t.text
                ),
            )),
            Some(t) => {
                self.pos += 1;
                Ok(t.text)
            }
        }
    }

    /// Line of the token read last.
    fn line(&self) -> usize {
        self.pos
            .checked_sub(1)
            .and_then(|p| self.tokens.get(p))
            .map_or(0, |t| t.line)
    }

    fn parse<T: std::str::FromStr>(&mut self, what: &str) -> Result<T, FeError> {
        let text = self.token(what)?;
        text.parse().map_err(|_| {
            self.err(
                self.line(),
                format!("{what}: `{text}` is not a valid number"),
            )
        })
    }

    fn usize(&mut self, what: &str) -> Result<usize, FeError> {
        self.parse(what)
    }

    fn int(&mut self, what: &str) -> Result<i64, FeError> {
        self.parse(what)
    }

    fn float(&mut self, what: &str) -> Result<f64, FeError> {
        let v: f64 = self.parse(what)?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.err(self.line(), format!("{what}: `{v}` is not finite")))
        }
    }

    /// A count, bounded by the number of tokens left so that a corrupt count
    /// cannot reserve absurd amounts of memory.
    fn count(&mut self, what: &str) -> Result<usize, FeError> {
        let n = self.usize(what)?;
        if n > self.tokens.len() - self.pos {
            return Err(self.err(
                self.line(),
                format!(
                    "truncated {}: {what} is {n}, more than the file holds",
                    self.section
                ),
            ));
        }
        Ok(n)
    }

    /// Reads the `$End...` token closing the current section.
    fn end(&mut self) -> Result<(), FeError> {
        let want = format!("$End{}", &self.section[1..]);
        match self.tokens.get(self.pos) {
            Some(t) if t.text == want => {
                self.pos += 1;
                Ok(())
            }
            Some(t) => Err(self.err(t.line, format!("expected `{want}`, found `{}`", t.text))),
            None => Err(self.err(
                self.last_line(),
                format!("truncated {}: missing `{want}`", self.section),
            )),
        }
    }

    /// Skips an unknown section up to its `$End...` token.
    fn skip(&mut self) -> Result<(), FeError> {
        let want = format!("$End{}", &self.section[1..]);
        while let Some(t) = self.tokens.get(self.pos) {
            self.pos += 1;
            if t.text == want {
                return Ok(());
            }
        }
        Err(self.err(
            self.last_line(),
            format!("truncated {}: missing `{want}`", self.section),
        ))
    }

    /// A quoted physical name: the rest of the current line; the tokens of
    /// the line are consumed.
    fn quoted_rest_of_line(&mut self, line: usize) -> Result<String, FeError> {
        let text = self.lines.get(line.wrapping_sub(1)).copied().unwrap_or("");
        let name = match (text.find('"'), text.rfind('"')) {
            (Some(a), Some(b)) if b > a => text[a + 1..b].to_string(),
            _ => return Err(self.err(line, "physical name must be in double quotes")),
        };
        while self.tokens.get(self.pos).is_some_and(|t| t.line == line) {
            self.pos += 1;
        }
        Ok(name)
    }
}

/// What the sections hold before the mesh is assembled.
#[derive(Default)]
struct Raw {
    names: HashMap<(usize, i64), String>,
    /// Physical tags of each entity `(dim, tag)`.
    physicals: HashMap<(usize, i64), Vec<i64>>,
    nodes: Vec<[f64; 3]>,
    node_lines: Vec<usize>,
    node_index: HashMap<u64, usize>,
    blocks: Vec<Block>,
}

fn read_format(r: &mut Reader) -> Result<(), FeError> {
    let version = r.token("the version")?;
    let line = r.line();
    if version != "4.1" {
        return Err(r.err(
            line,
            format!("MSH version {version} is not supported (need 4.1; in Gmsh set Mesh.MshFileVersion = 4.1)"),
        ));
    }
    let file_type = r.usize("the file type")?;
    if file_type != 0 {
        return Err(r.err(
            r.line(),
            "binary MSH is not supported (in Gmsh set Mesh.Binary = 0)",
        ));
    }
    r.usize("the data size")?;
    r.end()
}

fn read_names(r: &mut Reader, raw: &mut Raw) -> Result<(), FeError> {
    let n = r.count("the number of physical names")?;
    for _ in 0..n {
        let dim = r.usize("a physical group's dimension")?;
        let tag = r.int("a physical tag")?;
        let name = r.quoted_rest_of_line(r.line())?;
        raw.names.insert((dim, tag), name);
    }
    r.end()
}

fn read_entities(r: &mut Reader, raw: &mut Raw) -> Result<(), FeError> {
    let mut counts = [0usize; 4];
    for (dim, c) in counts.iter_mut().enumerate() {
        *c = r.count(&format!("the number of {dim}D entities"))?;
    }
    for (dim, &n) in counts.iter().enumerate() {
        for _ in 0..n {
            let tag = r.int("an entity tag")?;
            let coords = if dim == 0 { 3 } else { 6 };
            for _ in 0..coords {
                r.float("an entity's coordinates")?;
            }
            let np = r.count("the number of physical tags")?;
            let mut tags = Vec::with_capacity(np);
            for _ in 0..np {
                tags.push(r.int("a physical tag")?);
            }
            if dim > 0 {
                let nb = r.count("the number of bounding entities")?;
                for _ in 0..nb {
                    r.int("a bounding entity tag")?;
                }
            }
            raw.physicals.insert((dim, tag), tags);
        }
    }
    r.end()
}

fn read_nodes(r: &mut Reader, raw: &mut Raw) -> Result<(), FeError> {
    let blocks = r.count("the number of node blocks")?;
    let total = r.usize("the number of nodes")?;
    let header = r.line();
    r.usize("the smallest node tag")?;
    r.usize("the largest node tag")?;
    for _ in 0..blocks {
        let dim = r.usize("a node block's entity dimension")?;
        r.int("a node block's entity tag")?;
        let parametric = r.usize("a node block's parametric flag")?;
        let n = r.count("a node block's node count")?;
        let extra = if parametric == 1 { dim } else { 0 };
        let first = raw.nodes.len();
        for _ in 0..n {
            let tag: u64 = r.parse("a node tag")?;
            if raw.node_index.insert(tag, raw.nodes.len()).is_some() {
                return Err(r.err(r.line(), format!("node tag {tag} appears twice")));
            }
            raw.nodes.push([0.0; 3]);
            raw.node_lines.push(0);
        }
        for k in 0..n {
            let mut p = [0.0; 3];
            for v in &mut p {
                *v = r.float("a node coordinate")?;
            }
            raw.node_lines[first + k] = r.line();
            raw.nodes[first + k] = p;
            for _ in 0..extra {
                r.float("a parametric coordinate")?;
            }
        }
    }
    if raw.nodes.len() != total {
        return Err(r.err(
            header,
            format!(
                "the header announces {total} nodes but the blocks hold {}",
                raw.nodes.len()
            ),
        ));
    }
    r.end()
}

fn read_elements(r: &mut Reader, raw: &mut Raw) -> Result<(), FeError> {
    let blocks = r.count("the number of element blocks")?;
    let total = r.usize("the number of elements")?;
    let header = r.line();
    r.usize("the smallest element tag")?;
    r.usize("the largest element tag")?;
    let mut seen = 0;
    for _ in 0..blocks {
        let dim = r.usize("an element block's entity dimension")?;
        let line = r.line();
        let entity = r.int("an element block's entity tag")?;
        let code = r.int("an element type")?;
        let kind = Kind::from_code(code).ok_or_else(|| {
            r.err(
                line,
                format!(
                    "element type {code} is not supported (supported: 1 line2, 8 line3, \
                     3 quad4, 10 quad9, 5 hex8, 15 point)"
                ),
            )
        })?;
        if kind.dim() != dim {
            return Err(r.err(
                line,
                format!(
                    "element type {code} ({}D) in a block of {dim}D entity {entity}",
                    kind.dim()
                ),
            ));
        }
        let n = r.count("an element block's element count")?;
        let mut block = Block {
            dim,
            entity,
            kind,
            line,
            nodes: Vec::with_capacity(n * kind.nodes()),
            lines: Vec::with_capacity(n),
        };
        for _ in 0..n {
            let tag = r.usize("an element tag")?;
            block.lines.push(r.line());
            for _ in 0..kind.nodes() {
                let node: u64 = r.parse("an element's node tag")?;
                let &index = raw.node_index.get(&node).ok_or_else(|| {
                    r.err(
                        r.line(),
                        format!("element {tag} refers to node {node}, which is not in $Nodes"),
                    )
                })?;
                block.nodes.push(index);
            }
            // Each element is one line: a further token on it means the
            // element has more nodes than its type.
            let more = r
                .tokens
                .get(r.pos)
                .is_some_and(|t| t.line == r.line() && !t.text.starts_with('$'));
            if more {
                return Err(r.err(
                    r.line(),
                    format!(
                        "element {tag} has more than the {} nodes of type {code}",
                        kind.nodes()
                    ),
                ));
            }
        }
        seen += n;
        raw.blocks.push(block);
    }
    if seen != total {
        return Err(r.err(
            header,
            format!("the header announces {total} elements but the blocks hold {seen}"),
        ));
    }
    r.end()
}

impl Mesh {
    /// Reads a Gmsh MSH 4.1 ASCII file (see the [module docs](self)).
    pub fn read_gmsh(path: &Path) -> Result<Mesh, FeError> {
        let file = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| FeError::MeshFile {
            file: file.clone(),
            line: 0,
            reason: format!("cannot read: {e}"),
        })?;
        let text = String::from_utf8(bytes).map_err(|_| FeError::MeshFile {
            file: file.clone(),
            line: 0,
            reason: "not UTF-8 text (a binary MSH file?)".into(),
        })?;
        Mesh::from_gmsh_str(&text, &file)
    }

    /// Parses the text of a Gmsh MSH 4.1 ASCII file; `file` names it in
    /// errors (see the [module docs](self)).
    pub fn from_gmsh_str(text: &str, file: &str) -> Result<Mesh, FeError> {
        let mut r = Reader::new(text, file);
        let mut raw = Raw::default();
        let mut have_format = false;
        while let Some(t) = r.tokens.get(r.pos) {
            let (head, line) = (t.text, t.line);
            r.pos += 1;
            if !head.starts_with('$') || head.starts_with("$End") {
                return Err(r.err(
                    line,
                    format!("expected a section such as `$Nodes`, found `{head}`"),
                ));
            }
            if !have_format && head != "$MeshFormat" {
                return Err(r.err(
                    line,
                    "not a Gmsh MSH file: it must start with `$MeshFormat`",
                ));
            }
            r.section = head.to_string();
            match head {
                "$MeshFormat" => {
                    read_format(&mut r)?;
                    have_format = true;
                }
                "$PhysicalNames" => read_names(&mut r, &mut raw)?,
                "$Entities" => read_entities(&mut r, &mut raw)?,
                "$Nodes" => read_nodes(&mut r, &mut raw)?,
                "$Elements" => read_elements(&mut r, &mut raw)?,
                "$PartitionedEntities" => {
                    return Err(r.err(line, "partitioned meshes are not supported"))
                }
                _ => r.skip()?,
            }
        }
        if !have_format {
            return Err(r.err(1, "not a Gmsh MSH file: no `$MeshFormat` section"));
        }
        assemble(&r, raw)
    }
}

/// Builds the mesh from the sections read.
fn assemble(r: &Reader, raw: Raw) -> Result<Mesh, FeError> {
    let Some(dim) = raw.blocks.iter().map(|b| b.dim).max().filter(|&d| d >= 2) else {
        return Err(r.err(
            r.last_line(),
            "no 2D or 3D elements (quadrilaterals or hexahedra) in the file",
        ));
    };
    let mut cell_blocks = raw.blocks.iter().filter(|b| b.dim == dim);
    let first = cell_blocks.next().ok_or_else(|| r.err(0, "no cells"))?;
    let Kind::Cell(cell_type) = first.kind else {
        return Err(r.err(first.line, "no cells"));
    };
    if let Some(b) = cell_blocks.find(|b| b.kind != first.kind) {
        return Err(r.err(
            b.line,
            format!(
                "{} cells after {} cells (line {}): a mesh holds one cell type",
                b.kind.name(),
                first.kind.name(),
                first.line
            ),
        ));
    }
    if dim == 2 {
        if let Some(k) = raw.nodes.iter().position(|p| p[2] != 0.0) {
            return Err(r.err(
                raw.node_lines[k],
                format!(
                    "a 2D mesh must lie in the plane z = 0 (z = {})",
                    raw.nodes[k][2]
                ),
            ));
        }
    }
    let group_name = |d: usize, tag: i64| {
        raw.names
            .get(&(d, tag))
            .cloned()
            .unwrap_or_else(|| format!("physical_{tag}"))
    };
    let physicals = |b: &Block| {
        raw.physicals
            .get(&(b.dim, b.entity))
            .map_or(&[][..], |v| v.as_slice())
    };

    let mut mesh = Mesh::empty(dim, cell_type);
    mesh.nodes = raw.nodes.clone();
    let tagged = raw
        .blocks
        .iter()
        .any(|b| b.dim == dim && !physicals(b).is_empty());
    let facet = cell_type.facet();
    let mut node_sets: BTreeMap<String, BTreeSet<usize>> = BTreeMap::new();
    for b in &raw.blocks {
        let tags = physicals(b);
        if b.dim == dim {
            let first_cell = mesh.cell_count();
            for (k, (cell, &line)) in b
                .nodes
                .chunks_exact(cell_type.nodes())
                .zip(&b.lines)
                .enumerate()
            {
                let x: Vec<[f64; 3]> = cell.iter().map(|&n| raw.nodes[n]).collect();
                let jac = corner_jacobians(cell_type, &x);
                let bad = jac
                    .iter()
                    .position(|&j| if dim == 2 { j <= 0.0 } else { j < 0.0 });
                if let Some(c) = bad {
                    return Err(r.err(
                        line,
                        format!(
                            "inverted element: Jacobian determinant {:.3e} at corner {c}{}",
                            jac[c],
                            if dim == 2 {
                                " (corners must turn counter-clockwise)"
                            } else {
                                ""
                            }
                        ),
                    ));
                }
                mesh.cells.extend_from_slice(cell);
                let e = first_cell + k;
                if !tagged {
                    mesh.regions.entry("body".into()).or_default().push(e);
                } else if tags.is_empty() {
                    mesh.regions.entry("unassigned".into()).or_default().push(e);
                }
                for &t in tags {
                    mesh.regions.entry(group_name(dim, t)).or_default().push(e);
                }
            }
            continue;
        }
        for &t in tags {
            let name = group_name(b.dim, t);
            if b.dim + 1 == dim {
                if Some(b.kind) != facet.map(Kind::Cell) {
                    return Err(r.err(
                        b.line,
                        format!(
                            "physical group `{name}`: {} facets do not bound {cell_type:?} cells",
                            b.kind.name(),
                        ),
                    ));
                }
                if let Some(ft) = facet {
                    mesh.facet_sets
                        .entry(name.clone())
                        .or_insert_with(|| FacetSet {
                            cell_type: ft,
                            nodes: Vec::new(),
                        })
                        .nodes
                        .extend_from_slice(&b.nodes);
                }
            }
            node_sets
                .entry(name)
                .or_default()
                .extend(b.nodes.iter().copied());
        }
    }
    mesh.node_sets = node_sets
        .into_iter()
        .map(|(k, v)| (k, v.into_iter().collect()))
        .collect();
    mesh.validate().map_err(|e| r.err(0, e.to_string()))?;
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two unit squares side by side, sparse node tags, a physical surface
    /// `left` on entity 1 and an untagged surface 2, a physical curve `base`
    /// and a physical point `pin`.
    fn two_squares() -> String {
        r#"$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
3
0 9 "pin"
1 7 "base"
2 5 "left"
$EndPhysicalNames
$Entities
1 1 2 0
1 0 0 0 1 9
1 0 0 0 2 0 0 1 7 0
1 0 0 0 1 1 0 1 5 0
2 1 0 0 2 1 0 0 0
$EndEntities
$Nodes
2 6 10 60
2 1 0 3
10
20
30
0 0 0
1 0 0
0 1 0
2 2 0 3
40
50
60
1 1 0
2 0 0
2 1 0
$EndNodes
$Elements
4 4 1 4
2 1 3 1
1 10 20 40 30
2 2 3 1
2 20 50 60 40
1 1 1 1
3 10 20
0 1 15 1
4 10
$EndElements
"#
        .to_string()
    }

    fn file_err(text: &str) -> (usize, String) {
        match Mesh::from_gmsh_str(text, "t.msh") {
            Err(FeError::MeshFile { file, line, reason }) => {
                assert_eq!(file, "t.msh");
                (line, reason)
            }
            other => panic!("expected a file error, got {other:?}"),
        }
    }

    #[test]
    fn sparse_tags_regions_and_sets() {
        let m = Mesh::from_gmsh_str(&two_squares(), "t.msh").unwrap();
        assert_eq!((m.dim, m.cell_type), (2, CellType::Quad4));
        assert_eq!(m.nodes.len(), 6);
        assert_eq!(m.nodes[3], [1.0, 1.0, 0.0]);
        assert_eq!(m.cells, vec![0, 1, 3, 2, 1, 4, 5, 3]);
        assert_eq!(m.region("left").unwrap(), &[0]);
        assert_eq!(m.region("unassigned").unwrap(), &[1]);
        assert_eq!(m.facet_set("base").unwrap().nodes, vec![0, 1]);
        assert_eq!(m.node_set("base").unwrap(), &[0, 1]);
        assert_eq!(m.node_set("pin").unwrap(), &[0]);
    }

    #[test]
    fn without_physical_surfaces_all_cells_are_body() {
        let text = two_squares().replace("1 0 0 0 1 1 0 1 5 0", "1 0 0 0 1 1 0 0 0");
        let m = Mesh::from_gmsh_str(&text, "t.msh").unwrap();
        assert_eq!(m.region("body").unwrap(), &[0, 1]);
        assert_eq!(m.regions.len(), 1);
    }

    #[test]
    fn wrong_version_binary_and_missing_header() {
        let (line, reason) = file_err(&two_squares().replace("4.1 0 8", "2.2 0 8"));
        assert_eq!(line, 2);
        assert!(reason.contains("version 2.2"), "{reason}");
        let (_, reason) = file_err(&two_squares().replace("4.1 0 8", "4.1 1 8"));
        assert!(reason.contains("binary"), "{reason}");
        let (line, reason) = file_err("$Nodes\n0 0 0 0\n$EndNodes\n");
        assert_eq!(line, 1);
        assert!(reason.contains("$MeshFormat"), "{reason}");
    }

    #[test]
    fn unsupported_element_type() {
        // A triangle block (type 2).
        let (line, reason) = file_err(&two_squares().replace("2 2 3 1\n", "2 2 2 1\n"));
        assert_eq!(line, 38);
        assert!(reason.contains("element type 2"), "{reason}");
        let (_, reason) = file_err(&two_squares().replace("2 2 3 1\n", "2 2 99 1\n"));
        assert!(reason.contains("element type 99"), "{reason}");
    }

    #[test]
    fn element_refers_to_a_missing_node() {
        let (line, reason) = file_err(&two_squares().replace("2 20 50 60 40", "2 20 50 61 40"));
        assert_eq!(line, 39);
        assert!(reason.contains("node 61"), "{reason}");
    }

    #[test]
    fn truncated_sections() {
        let text = two_squares();
        let cut = text.find("2 2 3 1\n").unwrap();
        let (line, reason) = file_err(&text[..cut]);
        assert!(reason.contains("truncated $Elements"), "{reason}");
        assert_eq!(line, 37);
        // A node block cut short runs into $EndNodes.
        let (line, reason) = file_err(&text.replace("2 1 0\n$EndNodes", "$EndNodes"));
        assert!(reason.contains("truncated $Nodes"), "{reason}");
        assert_eq!(line, 32);
        let (_, reason) = file_err(&text.replace("$EndElements\n", ""));
        assert!(reason.contains("missing `$EndElements`"), "{reason}");
    }

    #[test]
    fn non_numeric_fields() {
        let (line, reason) = file_err(&two_squares().replace("1 1 0\n", "1 one 0\n"));
        assert_eq!(line, 30);
        assert!(reason.contains("`one`"), "{reason}");
        let (line, reason) = file_err(&two_squares().replace("3 10 20", "3 10 x20"));
        assert_eq!(line, 41);
        assert!(reason.contains("`x20`"), "{reason}");
        let (_, reason) = file_err(&two_squares().replace("2 0 0\n2 1 0", "2 0 0\n2 1 nan"));
        assert!(reason.contains("not finite"), "{reason}");
    }

    #[test]
    fn inverted_and_mixed_cells() {
        // Clockwise first cell.
        let (line, reason) = file_err(&two_squares().replace("1 10 20 40 30", "1 10 30 40 20"));
        assert_eq!(line, 37);
        assert!(reason.contains("inverted"), "{reason}");
        // A second cell block of another 2D type.
        let text = two_squares().replace(
            "2 2 3 1\n2 20 50 60 40",
            "2 2 10 1\n2 20 50 60 40 10 20 30 40 50",
        );
        let (line, reason) = file_err(&text);
        assert_eq!(line, 38);
        assert!(reason.contains("one cell type"), "{reason}");
    }

    #[test]
    fn facets_of_the_wrong_type_and_planarity() {
        let text = two_squares().replace("1 1 1 1\n3 10 20", "1 1 8 1\n3 10 20 50");
        let (line, reason) = file_err(&text);
        assert_eq!(line, 40);
        assert!(reason.contains("base"), "{reason}");
        let (line, reason) = file_err(&two_squares().replace("2 1 0\n$End", "2 1 0.5\n$End"));
        assert_eq!(line, 32);
        assert!(reason.contains("z = 0"), "{reason}");
    }

    #[test]
    fn counts_disagreeing_with_headers() {
        let (line, reason) = file_err(&two_squares().replace("4 4 1 4", "4 5 1 4"));
        assert_eq!(line, 35);
        assert!(reason.contains("announces 5 elements"), "{reason}");
        let (_, reason) = file_err(&two_squares().replace("4 10\n", "4 10 20\n"));
        assert!(reason.contains("more than the 1 nodes"), "{reason}");
    }

    #[test]
    fn unknown_sections_are_skipped_and_io_errors_name_the_file() {
        let text = two_squares().replace("$Nodes", "$Comments\nmade by hand\n$EndComments\n$Nodes");
        assert!(Mesh::from_gmsh_str(&text, "t.msh").is_ok());
        match Mesh::read_gmsh(Path::new("/nonexistent/x.msh")) {
            Err(FeError::MeshFile { file, line: 0, .. }) => assert!(file.ends_with("x.msh")),
            other => panic!("{other:?}"),
        }
    }
}
