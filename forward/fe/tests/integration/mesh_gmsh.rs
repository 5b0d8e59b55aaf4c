//! Reads the Gmsh fixtures in `tests/data` (made by
//! `tests/data/make_gmsh_fixtures.py` with gmsh 4.15.2) and checks them
//! against what the script asked Gmsh for. The expected counts were taken
//! from Gmsh's own API on the same files.

use std::path::PathBuf;

use palpate_fe::mesh::jacobian::corner_jacobians;
use palpate_fe::mesh::{CellType, Mesh};

const CENTRE: [f64; 2] = [5.0, 3.0];
const RADIUS: f64 = 1.5;

fn fixture(name: &str) -> Mesh {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name);
    Mesh::read_gmsh(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn radius(p: [f64; 3]) -> f64 {
    (p[0] - CENTRE[0]).hypot(p[1] - CENTRE[1])
}

/// Shoelace area of the corner polygon of a quadrilateral.
fn corner_area(m: &Mesh, cell: &[usize]) -> f64 {
    (0..4)
        .map(|k| {
            let (p, q) = (m.nodes[cell[k]], m.nodes[cell[(k + 1) % 4]]);
            0.5 * (p[0] * q[1] - q[0] * p[1])
        })
        .sum()
}

/// Checks shared by the first- and second-order inclusion meshes.
fn check_inclusion(m: &Mesh, cell_type: CellType, facet_nodes: usize, side_nodes: [usize; 5]) {
    m.validate().unwrap();
    assert_eq!((m.dim, m.cell_type), (2, cell_type));
    assert_eq!(m.cell_count(), 272);
    assert_eq!(
        m.regions.keys().collect::<Vec<_>>(),
        vec!["inclusion", "matrix"]
    );
    assert_eq!(m.region("inclusion").unwrap().len(), 36);
    assert_eq!(m.region("matrix").unwrap().len(), 236);
    // The first nodes are the geometry's corner points, in Gmsh's order.
    assert_eq!(m.nodes[0], [0.0, 0.0, 0.0]);
    assert_eq!(m.nodes[1], [10.0, 0.0, 0.0]);
    assert_eq!(m.nodes[3], [10.0, 6.0, 0.0]);
    assert_eq!(m.node_set("origin").unwrap(), &[0]);

    let sides = ["bottom", "top", "left", "right", "interface"];
    let facets = [20, 20, 12, 12, 20];
    for ((name, nf), nn) in sides.iter().zip(facets).zip(side_nodes) {
        let fs = m.facet_set(name).unwrap();
        assert_eq!(fs.cell_type.nodes(), facet_nodes, "{name}");
        assert_eq!(fs.len(), nf, "{name}");
        assert_eq!(m.node_set(name).unwrap().len(), nn, "{name}");
    }
    let on = |name: &str, f: &dyn Fn([f64; 3]) -> bool| {
        m.node_set(name).unwrap().iter().all(|&n| f(m.nodes[n]))
    };
    assert!(on("bottom", &|p| p[1] == 0.0));
    assert!(on("top", &|p| p[1] == 6.0));
    assert!(on("left", &|p| p[0] == 0.0));
    assert!(on("right", &|p| p[0] == 10.0));
    assert!(on("interface", &|p| (radius(p) - RADIUS).abs() < 1e-9));

    // The inclusion's cells lie inside the circle, the matrix's outside.
    for &e in m.region("inclusion").unwrap() {
        assert!(m
            .cell(e)
            .iter()
            .all(|&n| radius(m.nodes[n]) <= RADIUS + 1e-9));
    }
    for &e in m.region("matrix").unwrap() {
        assert!(m
            .cell(e)
            .iter()
            .all(|&n| radius(m.nodes[n]) >= RADIUS - 1e-9));
    }
    // The corner polygons tile the rectangle; the inclusion's is an inscribed
    // polygon of the disk with 20 sides.
    let area = |r: &str| -> f64 {
        m.region(r)
            .unwrap()
            .iter()
            .map(|&e| corner_area(m, m.cell(e)))
            .sum()
    };
    assert!((area("inclusion") + area("matrix") - 60.0).abs() < 1e-9);
    let polygon = 0.5 * 20.0 * RADIUS * RADIUS * (2.0 * std::f64::consts::PI / 20.0).sin();
    assert!(
        (area("inclusion") - polygon).abs() < 1e-9,
        "{}",
        area("inclusion")
    );
}

#[test]
fn inclusion_in_quad4() {
    let m = fixture("inclusion_quad4.msh");
    assert_eq!(m.nodes.len(), 305);
    check_inclusion(&m, CellType::Quad4, 2, [21, 21, 13, 13, 20]);
}

#[test]
fn inclusion_in_quad9() {
    let m = fixture("inclusion_quad9.msh");
    assert_eq!(m.nodes.len(), 1153);
    check_inclusion(&m, CellType::Quad9, 3, [41, 41, 25, 25, 40]);
    // Mid-edge nodes of the interface lie on the circle, not on the chords.
    let fs = m.facet_set("interface").unwrap();
    assert!(fs
        .iter()
        .all(|f| (radius(m.nodes[f[2]]) - RADIUS).abs() < 1e-9));
}

#[test]
fn hex_box() {
    let m = fixture("box_hex8.msh");
    m.validate().unwrap();
    assert_eq!((m.dim, m.cell_type), (3, CellType::Hex8));
    assert_eq!(m.nodes.len(), 45);
    assert_eq!(m.cell_count(), 16);
    assert_eq!(m.regions.keys().collect::<Vec<_>>(), vec!["box"]);
    assert_eq!(m.region("box").unwrap().len(), 16);
    for (name, z) in [("bottom", 0.0), ("top", 1.0)] {
        let fs = m.facet_set(name).unwrap();
        assert_eq!((fs.cell_type, fs.len()), (CellType::Quad4, 8));
        let set = m.node_set(name).unwrap();
        assert_eq!(set.len(), 15);
        assert!(set.iter().all(|&n| m.nodes[n][2] == z));
    }
    // Transfinite 4 x 2 x 2: every cell is a cube of side 0.5, so dx/dxi =
    // 0.25 I at every corner (positive: Gmsh order).
    for c in m.cells() {
        let x: Vec<[f64; 3]> = c.iter().map(|&n| m.nodes[n]).collect();
        for j in corner_jacobians(CellType::Hex8, &x) {
            assert!((j - 0.25f64.powi(3)).abs() < 1e-12, "{j}");
        }
    }
}

/// Elevating Gmsh's first-order mesh gives the node and set counts of the
/// second-order mesh Gmsh made from the same geometry (one node per edge and
/// per cell), though its curved interface stays polygonal.
#[test]
fn quad4_fixture_elevated_matches_gmsh_second_order_counts() {
    let q4 = fixture("inclusion_quad4.msh").to_quadratic().unwrap();
    let q9 = fixture("inclusion_quad9.msh");
    q4.validate().unwrap();
    assert_eq!(q4.nodes.len(), q9.nodes.len());
    assert_eq!(q4.cell_count(), q9.cell_count());
    assert_eq!(q4.regions, q9.regions);
    for name in q9.facet_sets.keys() {
        let (a, b) = (q4.facet_set(name).unwrap(), q9.facet_set(name).unwrap());
        assert_eq!((a.cell_type, a.len()), (b.cell_type, b.len()), "{name}");
    }
    for (name, set) in &q9.node_sets {
        assert_eq!(q4.node_set(name).unwrap().len(), set.len(), "{name}");
    }
}
