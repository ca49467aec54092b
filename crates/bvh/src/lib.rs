//! Ball-and-stick ray casting geometry (paper §4.1, §4.3): primitives, a binned SAH BVH built
//! in parallel (plus the paper's full-sweep builder as a quality reference), SIMD intersection
//! kernels generic over [`spmd::Simd`], coherent packet traversal, single-ray traversal and an 8-wide BVH for
//! incoherent single rays.
//!
//! Units: lengths in Ångström (Å); ray directions are unit vectors, so `t` is in Å too.
//!
//! ```
//! use bvh::{Bvh, Geometry, Ray};
//! let g = Geometry::from_atoms(&[0.0, 1.5], &[0.0; 2], &[0.0; 2], &[0.5; 2], &[], &[[0, 1]], 0.15);
//! let bvh = Bvh::build(&g);
//! bvh.validate(&g).unwrap();
//! let hit = bvh.intersect_ray(&Ray::new([0.0, 0.0, -10.0], [0.0, 0.0, 1.0])).unwrap();
//! assert!((hit.t - 9.5).abs() < 1e-5);
//! ```

#![warn(missing_docs)]
mod beam;
mod build;
pub mod compact;
mod geometry;
mod intersect;
mod query;
pub mod scenes;
mod spans;
mod traverse;
mod tree;
mod wide;

pub use beam::{Corners, Frusta, Origin};
pub use build::{BuildOptions, Cancelled, Watch, CLUSTER_ABOVE, CLUSTER_UPTO, MAX_BINS};
pub use geometry::{Aabb, Balls, Geometry, Prim, PrimRecord, Sticks};
pub use intersect::{
    end_point, intersect_ball, intersect_bond, intersect_record, ray_bond, ray_cap, ray_cylinder,
    ray_sphere, surface, Surface,
};
pub use query::{Query, Stacks, Traversal};
pub use spans::Span;
pub use traverse::{
    box_test, load_packet, slab_test, unpack_hits, Hit, PacketHit, Ray, RayPacket, BOX_GROW,
};
pub use tree::{BuildStats, Builder, Bvh, Node, INNER, LEAF_MAX};
pub use wide::{WideBvh, WideEntry, WideNode, WIDTH};
