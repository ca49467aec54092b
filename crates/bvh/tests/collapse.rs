//! The parallel collapse (`CompactBvh::new`, `compact/collapse.rs`) against one thread's
//! depth-first recursion kept here (the one `CompactBvh::new` used before, over the same
//! `compact::cut`): the same node array bit for bit, the same root, depth and slot ids, on
//! scenes deep enough that the subtrees below the threaded levels are written too.

use bvh::compact::{cut, CompactBvh, QNode, EMPTY};
use bvh::scenes::random_molecule;
use bvh::{BuildOptions, Bvh, Geometry};

/// One thread's collapse: the node for binary inner node `i`, then the subtree of each inner
/// child in child order; returns the node's index.
fn serial(bvh: &Bvh, i: usize, depth: usize, nodes: &mut Vec<QNode>, deepest: &mut usize) -> u32 {
    *deepest = (*deepest).max(depth);
    let (kids, n) = cut(bvh, i);
    let at = nodes.len();
    nodes.push(QNode::over(&bvh.nodes, &kids[..n]));
    for (c, &k) in kids[..n].iter().enumerate() {
        if !bvh.nodes[k].is_leaf() {
            nodes[at].child[c] = serial(bvh, k, depth + 1, nodes, deepest);
        }
    }
    at as u32
}

/// Every bit of a node, field by field (64 bytes, no padding): origin, scale, lo, hi, child.
fn bits(q: &QNode) -> [u32; 16] {
    let mut w = [0u32; 16];
    for a in 0..3 {
        w[a] = q.origin[a].to_bits();
        w[3 + a] = q.scale[a].to_bits();
        w[6 + a] = u32::from_le_bytes(q.lo[a]);
        w[9 + a] = u32::from_le_bytes(q.hi[a]);
    }
    w[12..].copy_from_slice(&q.child);
    w
}

/// Builds the tree over `g` with `opt` and compares `CompactBvh::new` with [`serial`];
/// returns the node count and depth.
fn same_as_serial(g: &Geometry, opt: &BuildOptions) -> (usize, usize) {
    let bvh = Bvh::build_with(g, opt);
    let c = CompactBvh::new(g, &bvh).unwrap();
    c.validate(g).unwrap();
    assert!(!bvh.nodes[0].is_leaf(), "scene too small for a 4-wide node");
    let (mut nodes, mut depth) = (Vec::new(), 0);
    assert_eq!(serial(&bvh, 0, 0, &mut nodes, &mut depth), 0);
    assert_eq!(c.root, 0);
    assert_eq!(c.depth, depth, "depth");
    assert_eq!(c.prim_ids, bvh.prim_ids, "slot ids");
    assert_eq!(c.nodes.len(), nodes.len(), "node count");
    if let Some(i) = (0..nodes.len()).find(|&i| bits(&c.nodes[i]) != bits(&nodes[i])) {
        panic!(
            "node {i} of {} differs:\nparallel {:?}\nserial   {:?}",
            nodes.len(),
            c.nodes[i],
            nodes[i]
        );
    }
    assert!(c.nodes.iter().all(|q| q.child[0] != EMPTY));
    (nodes.len(), depth)
}

#[test]
fn parallel_collapse_equals_the_recursion() {
    // 200K atoms are far deeper than the 6 threaded levels of 4-wide nodes.
    for (atoms, clustered) in [
        (100, false),
        (5_000, true),
        (60_000, false),
        (200_000, true),
    ] {
        let g = random_molecule(atoms, clustered, 11 + atoms as u64);
        for cluster_above in [0, usize::MAX] {
            let opt = BuildOptions {
                cluster_above,
                ..Default::default()
            };
            let (n, depth) = same_as_serial(&g, &opt);
            if atoms >= 60_000 {
                assert!(
                    depth > 6,
                    "{atoms} atoms: depth {depth}, no serial subtrees"
                );
            }
            eprintln!("{atoms} atoms, cluster_above {cluster_above}: {n} nodes, depth {depth}");
        }
    }
}

/// The 740K and 4.8 M scenes of `examples/build_time.rs` (its clustered build). Slow in a
/// debug build: `cargo test --release -p bvh --test collapse -- --ignored`.
#[test]
#[ignore]
fn parallel_collapse_equals_the_recursion_build_time_scenes() {
    for atoms in [740_000, 4_800_000] {
        let g = random_molecule(atoms, false, 7);
        let opt = BuildOptions {
            cluster_above: 0,
            ..Default::default()
        };
        let (n, depth) = same_as_serial(&g, &opt);
        eprintln!("{atoms} atoms (build_time's scene): {n} nodes, depth {depth}");
    }
}
