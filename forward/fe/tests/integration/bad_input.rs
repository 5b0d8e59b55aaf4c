//! Bad input: a mesh file with a missing node, an inverted
//! element, an unknown region name, a tool starting inside the body and a
//! loading channel that no boundary condition uses each give a clear error
//! naming the file and line or the field, never a panic. Also a dimension
//! mismatch and conflicting Dirichlet conditions. Every test asserts on the
//! message text, so a vaguer message fails it.

use std::sync::Arc;

use palpate_fe::body::{RegionMaterial, SolidBody};
use palpate_fe::contact::{ContactOptions, RigidContact};
use palpate_fe::contribution::Contribution;
use palpate_fe::dofs::Dirichlet;
use palpate_fe::kernel::{kernel_for, ElementKernel, PressureSpace};
use palpate_fe::kinematics::Kinematics;
use palpate_fe::material::NeoHookeanIso;
use palpate_fe::mesh::{CellType, Mesh};
use palpate_fe::motion::ToolMotion;
use palpate_fe::{
    ContactPoints, FeError, Profile2d, Revolution3d, RigidSurface, System, ToolShape,
};
use palpate_material::Volumetric;

const PLANE: Kinematics = Kinematics::PlaneStrain { thickness: 1.0 };

/// Two unit squares side by side (nodes 1..6, elements 1 and 2), no
/// physical groups: every cell is in region `body`.
const TWO_SQUARES: &str = "$MeshFormat
4.1 0 8
$EndMeshFormat
$Nodes
1 6 1 6
2 1 0 6
1
2
3
4
5
6
0 0 0
1 0 0
2 0 0
0 1 0
1 1 0
2 1 0
$EndNodes
$Elements
1 2 1 2
2 1 3 2
1 1 2 5 4
2 2 3 6 5
$EndElements
";

/// The 1-based line of `text` that is exactly `line`.
fn line_of(text: &str, line: &str) -> usize {
    text.lines()
        .position(|l| l == line)
        .unwrap_or_else(|| panic!("no line `{line}`"))
        + 1
}

/// The file error of `text` read as `bad.msh`: (line, rendered message).
fn file_error(text: &str) -> (usize, String) {
    match Mesh::from_gmsh_str(text, "bad.msh") {
        Err(e @ FeError::MeshFile { .. }) => {
            let FeError::MeshFile { ref file, line, .. } = e else {
                unreachable!()
            };
            assert_eq!(file, "bad.msh");
            (line, e.to_string())
        }
        other => panic!("expected a mesh file error, got {other:?}"),
    }
}

fn err<T>(r: Result<T, FeError>) -> FeError {
    match r {
        Ok(_) => panic!("bad input accepted"),
        Err(e) => e,
    }
}

fn square_mesh() -> Mesh {
    Mesh::tensor(&[0.0, 1.0, 2.0, 3.0], &[0.0, 1.0, 2.0])
}

fn cube_mesh() -> Mesh {
    let xs = [0.0, 1.0, 2.0];
    Mesh::tensor3(&xs, &xs, &xs)
}

fn body(mesh: &Mesh, kin: Kinematics, pressure: PressureSpace) -> Result<SolidBody, FeError> {
    SolidBody::new(
        "tissue",
        mesh,
        &["body"],
        kernel_for(mesh.cell_type, kin, pressure)?,
        false,
    )
}

fn material() -> RegionMaterial {
    RegionMaterial {
        material: Arc::new(NeoHookeanIso { c10: 0.5 }),
        volumetric: Volumetric::D1(0.1),
    }
}

fn options() -> ContactOptions {
    ContactOptions {
        friction: 0.0,
        penalty_normal: 1.0,
        penalty_tangent: 1.0,
        penetration_tol: 1e-6,
        points: ContactPoints::Nodes,
    }
}

#[test]
fn the_fixture_itself_is_good() {
    let m = Mesh::from_gmsh_str(TWO_SQUARES, "bad.msh").unwrap();
    assert_eq!((m.nodes.len(), m.cell_count()), (6, 2));
    assert!(body(&m, PLANE, PressureSpace::P0).is_ok());
}

#[test]
fn mesh_file_with_a_missing_node_names_file_and_line() {
    let bad_line = "2 2 3 7 5";
    let text = TWO_SQUARES.replace("2 2 3 6 5", bad_line);
    let (line, msg) = file_error(&text);
    assert_eq!(line, line_of(&text, bad_line));
    assert!(msg.starts_with(&format!("bad.msh:{line}: ")), "{msg}");
    assert!(
        msg.contains("element 2 refers to node 7, which is not in $Nodes"),
        "{msg}"
    );
}

#[test]
fn mesh_given_directly_with_a_missing_node_names_cell_and_node() {
    let mut m = square_mesh();
    m.cells[4 + 2] = 99; // cell 1, third node
    let msg = err(m.validate()).to_string();
    assert_eq!(msg, "mesh `cell 1`: node 99 does not exist (12 nodes)");
    // The body is built from such a mesh without indexing past the nodes.
    let msg = err(body(&m, PLANE, PressureSpace::P0)).to_string();
    assert!(msg.contains("cell 1") && msg.contains("node 99"), "{msg}");
}

#[test]
fn mesh_file_with_an_inverted_element_names_file_and_line() {
    // element 2 clockwise
    let bad_line = "2 2 5 6 3";
    let text = TWO_SQUARES.replace("2 2 3 6 5", bad_line);
    let (line, msg) = file_error(&text);
    assert_eq!(line, line_of(&text, bad_line));
    assert!(msg.starts_with(&format!("bad.msh:{line}: ")), "{msg}");
    assert!(msg.contains("inverted element"), "{msg}");
    assert!(msg.contains("counter-clockwise"), "{msg}");
}

/// The error of building a body on a mesh with an inverted cell: an
/// `InvalidMesh` naming the cell.
fn inverted(mesh: &Mesh, kin: Kinematics, pressure: PressureSpace, cell: usize) -> String {
    match err(body(mesh, kin, pressure)) {
        e @ FeError::InvalidMesh { .. } => {
            let msg = e.to_string();
            assert!(
                msg.starts_with(&format!("mesh `cell {cell}`: inverted")),
                "{msg}"
            );
            msg
        }
        other => panic!("expected an invalid mesh, got {other:?}"),
    }
}

#[test]
fn inverted_cells_given_directly_name_the_cell() {
    // A clockwise Quad4: cell 4 with its corners reversed.
    let mut m = square_mesh();
    m.cells[16..20].reverse();
    let msg = inverted(&m, PLANE, PressureSpace::P0, 4);
    assert!(msg.contains("counter-clockwise"), "{msg}");

    // An inverted Hex8: cell 5 with its bottom and top faces swapped.
    let mut m = cube_mesh();
    let c = &mut m.cells[5 * 8..6 * 8];
    let (bottom, top) = c.split_at_mut(4);
    bottom.swap_with_slice(top);
    let msg = inverted(&m, Kinematics::ThreeD, PressureSpace::P0, 5);
    assert!(msg.contains("bottom face"), "{msg}");

    // A Quad9 whose mid-node of edge 0-1 sits near corner 0: folded at
    // that corner although the cell's corners are in order.
    let mut m = square_mesh().to_quadratic().unwrap();
    let cell = 1;
    let ns = m.cell(cell).to_vec();
    let (a, b) = (m.nodes[ns[0]], m.nodes[ns[1]]);
    m.nodes[ns[4]] = std::array::from_fn(|i| a[i] + 0.1 * (b[i] - a[i]));
    let msg = inverted(&m, PLANE, PressureSpace::P1, cell);
    assert!(msg.contains("at corner 0"), "{msg}");
}

#[test]
fn unknown_region_names_the_region_and_the_known_ones() {
    let m = square_mesh();
    let kernel = kernel_for(CellType::Quad4, PLANE, PressureSpace::P0).unwrap();
    let e = err(SolidBody::new("tissue", &m, &["tumour"], kernel, false));
    assert_eq!(e.to_string(), "mesh `tumour`: no such region (have: body)");

    let mut b = body(&m, PLANE, PressureSpace::P0).unwrap();
    let e = err(b.set_material("tumour", material()));
    assert_eq!(
        e.to_string(),
        "configuration `material of region `tumour``: body `tissue` has no such region (have: body)"
    );
    assert!(b.set_material("body", material()).is_ok());
}

/// A contact of `surface` at `origin` translating by channel 0 against the
/// top of `mesh`.
fn contact(
    mesh: &Mesh,
    surface: Box<dyn RigidSurface>,
    origin: [f64; 3],
    kin: Kinematics,
) -> Result<RigidContact, FeError> {
    let down = if mesh.dim == 2 {
        [0.0, -1.0, 0.0]
    } else {
        [0.0, 0.0, -1.0]
    };
    RigidContact::new(
        "probe",
        surface,
        ToolMotion::translating(origin, vec![(0, down)]),
        mesh,
        "top",
        kin,
        options(),
        1,
    )
}

#[test]
fn tool_starting_inside_the_body_names_tool_and_node_2d() {
    let m = square_mesh();
    let sphere = || Box::new(Profile2d(ToolShape::Sphere { radius: 1.0 }));
    // touching the top (y = 2) at the axis is fine, 0.2 mm below is not
    assert!(contact(&m, sphere(), [0.0, 2.0, 0.0], Kinematics::Axisymmetric).is_ok());
    match err(contact(
        &m,
        sphere(),
        [0.0, 1.8, 0.0],
        Kinematics::Axisymmetric,
    )) {
        e @ FeError::ToolStartsInside { .. } => {
            let FeError::ToolStartsInside { node, gap, .. } = e else {
                unreachable!()
            };
            assert!(m.node_set("top").unwrap().contains(&node));
            assert!(gap < 0.0);
            let msg = e.to_string();
            assert!(
                msg.starts_with(&format!(
                    "tool `probe` starts inside the body at node {node} "
                )),
                "{msg}"
            );
        }
        other => panic!("expected a tool inside, got {other:?}"),
    }
}

#[test]
fn tool_starting_inside_the_body_names_tool_and_node_3d() {
    let m = cube_mesh();
    let sphere = || Box::new(Revolution3d(ToolShape::Sphere { radius: 1.5 }));
    assert!(contact(&m, sphere(), [1.0, 1.0, 2.0], Kinematics::ThreeD).is_ok());
    let e = err(contact(&m, sphere(), [1.0, 1.0, 1.9], Kinematics::ThreeD));
    let FeError::ToolStartsInside { node, .. } = e else {
        panic!("expected a tool inside, got {e:?}")
    };
    // the top node under the sphere's pole
    assert_eq!(m.nodes[node], [1.0, 1.0, 2.0]);
    let msg = e.to_string();
    assert!(
        msg.starts_with(&format!(
            "tool `probe` starts inside the body at node {node} (1.0000, 1.0000, 2.0000) mm"
        )),
        "{msg}"
    );
}

#[test]
fn loading_channel_used_by_nothing_is_named() {
    let m = square_mesh();
    let bcs = [
        Dirichlet::fixed("bottom", 0),
        Dirichlet::fixed("bottom", 1),
        Dirichlet::driven("top", 1, 0, -1.0),
    ];
    let parts = || -> Vec<Box<dyn Contribution>> {
        vec![Box::new(
            body(&square_mesh(), PLANE, PressureSpace::P0).unwrap(),
        )]
    };
    assert!(System::new(m.clone(), 2, parts(), &bcs, 1).is_ok());
    let e = err(System::new(m.clone(), 2, parts(), &bcs, 2));
    assert_eq!(
        e.to_string(),
        "configuration `channels`: loading channel 1 is used by no boundary condition and no tool (2 channels)"
    );
    // A channel that only a tool follows is used.
    let tool = RigidContact::new(
        "probe",
        Box::new(Profile2d(ToolShape::Platen)),
        ToolMotion::translating([0.0, 2.5, 0.0], vec![(1, [0.0, -1.0, 0.0])]),
        &m,
        "top",
        PLANE,
        options(),
        2,
    )
    .unwrap();
    assert_eq!(tool.channels(), vec![1]);
    let mut with_tool = parts();
    with_tool.push(Box::new(tool));
    assert!(System::new(m.clone(), 2, with_tool, &bcs, 2).is_ok());
    // Nothing drives channel 0 when the conditions hold everything fixed.
    let fixed = [Dirichlet::fixed("bottom", 0), Dirichlet::fixed("bottom", 1)];
    let e = err(System::new(m, 2, parts(), &fixed, 1));
    assert!(
        e.to_string().contains("loading channel 0 is used by no"),
        "{e}"
    );
}

#[test]
fn dimension_mismatches_are_named() {
    let cube = cube_mesh();
    let profile = || Box::new(Profile2d(ToolShape::Sphere { radius: 1.0 }));
    // a 2D surface on a 3D mesh, in 3D kinematics
    let e = err(contact(
        &cube,
        profile(),
        [1.0, 1.0, 3.0],
        Kinematics::ThreeD,
    ));
    assert_eq!(
        e.to_string(),
        "configuration `tool `probe``: a 2D surface in ThreeD kinematics"
    );
    // ... and in 2D kinematics
    let e = err(contact(&cube, profile(), [1.0, 1.0, 3.0], PLANE));
    assert!(
        e.to_string()
            .contains("tool `probe``: PlaneStrain { thickness: 1.0 } kinematics on a 3D mesh"),
        "{e}"
    );
    // a 2D motion must stay in the plane
    let m = square_mesh();
    let e = err(RigidContact::new(
        "probe",
        profile(),
        ToolMotion::translating([0.0, 3.0, 0.0], vec![(0, [0.0, -1.0, 0.5])]),
        &m,
        "top",
        PLANE,
        options(),
        1,
    ));
    assert!(e.to_string().contains("zero z components"), "{e}");
    // a 2D kernel for a 3D mesh
    let kernel: Box<dyn ElementKernel> =
        kernel_for(CellType::Quad4, PLANE, PressureSpace::P0).unwrap();
    let e = err(SolidBody::new("tissue", &cube, &["body"], kernel, false));
    assert_eq!(
        e.to_string(),
        "configuration `body `tissue``: kernel for Quad4 cells on a mesh of Hex8"
    );
    // two components per node on a 3D mesh
    let e = err(System::new(
        cube,
        2,
        vec![],
        &[Dirichlet::driven("top", 1, 0, 1.0)],
        1,
    ));
    assert_eq!(
        e.to_string(),
        "configuration `dim`: 2 components per node on a 3D mesh"
    );
}

#[test]
fn conflicting_dirichlet_conditions_are_named() {
    let m = square_mesh();
    let top_right = *m.node_set("top").unwrap().last().unwrap();
    let bcs = [
        Dirichlet::fixed("bottom", 1),
        Dirichlet::fixed("side", 1),
        Dirichlet::driven("top", 1, 0, -1.0),
    ];
    let parts: Vec<Box<dyn Contribution>> =
        vec![Box::new(body(&m, PLANE, PressureSpace::P0).unwrap())];
    let e = err(System::new(m, 2, parts, &bcs, 1));
    assert_eq!(
        e.to_string(),
        format!(
            "configuration `boundary condition 2 (node set `top`)`: node {top_right} component 1 is already Fixed"
        )
    );
}
