//! Model assembly: styles, radii, colours, BVH.

use std::sync::OnceLock;

use bvh::{Balls, BuildOptions, Bvh, Cancelled, Geometry, Prim, Watch, WideBvh};
use rayon::prelude::*;

use molecule::Cell;

use crate::colormap::Colormap;
use crate::periodic::{add_cell_edges, split_periodic_sticks};

/// Colour of the drawn simulation cell's edges: a mid grey, seen on white and dark backgrounds.
pub const CELL_COLOR: u32 = crate::rgba(128, 128, 128, 255);

/// How the molecule is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Style {
    /// Balls and sticks (stick ends hidden in the balls).
    BallAndStick,
    /// Sticks only, with round caps (licorice).
    Licorice,
    /// Balls only (space-filling with van der Waals radii).
    Spheres,
}

/// How atoms are coloured.
#[derive(Clone, Debug, PartialEq)]
pub enum Coloring {
    /// The per-atom colours passed to [`Model::new`] (e.g. CPK by element).
    PerAtom,
    /// A per-atom scalar mapped through a colormap; `range` = values mapped to 0 and 1
    /// (`None`: the finite min and max of the values).
    Scalar {
        /// One value per atom.
        values: Vec<f32>,
        /// Colormap.
        colormap: Colormap,
        /// Value range mapped onto the colormap.
        range: Option<(f32, f32)>,
    },
}

/// Geometry options (they decide what the BVH is built over).
#[derive(Clone, Debug, PartialEq)]
pub struct ModelOptions {
    /// Ball radius = per-atom radius × this (e.g. 0.5 with covalent radii, 1.0 with vdW).
    pub radius_scale: f32,
    /// Stick radius (Å).
    pub stick_radius: f32,
    /// Drawing style.
    pub style: Style,
    /// Colouring.
    pub coloring: Coloring,
    /// The simulation cell, used by `periodic_bonds` and `draw_cell`.
    pub cell: Option<Cell>,
    /// Draw bonds that cross the cell's periodic boundary as two half-sticks
    /// ([`split_periodic_sticks`]).
    pub periodic_bonds: bool,
    /// Draw the cell's edges as sticks of [`CELL_COLOR`] ([`add_cell_edges`]).
    pub draw_cell: bool,
}

impl Default for ModelOptions {
    fn default() -> Self {
        ModelOptions {
            radius_scale: 0.5,
            stick_radius: 0.15,
            style: Style::BallAndStick,
            coloring: Coloring::PerAtom,
            cell: None,
            periodic_bonds: false,
            draw_cell: false,
        }
    }
}

/// A renderable ball-and-stick scene: geometry, BVH, per-slot colours, bounding sphere.
#[derive(Clone, Debug)]
pub struct Model {
    /// Balls and sticks.
    pub geometry: Geometry,
    /// The BVH over them (its `stats` hold build time, node count, SAH cost, bytes).
    pub bvh: Bvh,
    /// Colour (packed RGBA8 as i32) of each BVH slot: the ball's atom, or a stick's first atom.
    pub slot_color_a: Vec<i32>,
    /// Colour of each slot's second half (sticks: atom b; balls: as `slot_color_a`).
    pub slot_color_b: Vec<i32>,
    /// Centre of the bounding sphere (Å).
    pub center: [f32; 3],
    /// Radius of the bounding sphere (Å), including ball radii.
    pub radius: f32,
    /// The values mapped to the colormap's ends when coloured by a scalar (Å-free: the
    /// column's units); `None` for per-atom colours.
    pub color_range: Option<(f32, f32)>,
    /// The 8-wide BVH for single incoherent rays, collapsed from `bvh` on first use.
    wide: OnceLock<WideBvh>,
}

impl Model {
    /// Builds a scene from atom positions (Å), per-atom base radius (Å, scaled by
    /// `opt.radius_scale`), per-atom colours (packed RGBA8, see [`crate::rgba`]) and bonds.
    /// Bonds with an atom index out of range are ignored. `colors` may be empty (grey).
    /// `watch`, if given, counts the primitives the BVH builder has placed (see
    /// [`Model::from_geometry`]), for a progress display, and can stop the build
    /// ([`Cancelled`]; never without a watch).
    /// Panics if `x`, `y`, `z` and `radius` differ in length.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        x: &[f32],
        y: &[f32],
        z: &[f32],
        radius: &[f32],
        colors: &[u32],
        bonds: &[[u32; 2]],
        opt: &ModelOptions,
        watch: Option<&Watch>,
    ) -> Result<Model, Cancelled> {
        let n = x.len();
        let radii: Vec<f32> = radius.iter().map(|r| r * opt.radius_scale).collect();
        let mut color_range = None;
        let colors: Vec<u32> = match &opt.coloring {
            Coloring::PerAtom => {
                if colors.len() == n {
                    colors.to_vec()
                } else {
                    vec![crate::rgba(200, 200, 200, 255); n]
                }
            }
            Coloring::Scalar {
                values,
                colormap,
                range,
            } => {
                let (lo, hi) = range.unwrap_or_else(|| {
                    values
                        .iter()
                        .filter(|v| v.is_finite())
                        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &v| {
                            (a.min(v), b.max(v))
                        })
                });
                color_range = Some((lo, hi));
                let span = if hi > lo { hi - lo } else { 1.0 };
                (0..n)
                    .map(|i| {
                        let v = values.get(i).copied().unwrap_or(f32::NAN);
                        let [r, g, b] = colormap.map((v - lo) / span);
                        crate::rgba(r, g, b, 255)
                    })
                    .collect()
            }
        };
        let bonds: &[[u32; 2]] = if opt.style == Style::Spheres {
            &[]
        } else {
            bonds
        };
        // The scaled radii and the colours become the balls' own arrays (moved, not copied:
        // 8 B per atom less at the peak of the model build).
        let balls = Balls {
            x: x.to_vec(),
            y: y.to_vec(),
            z: z.to_vec(),
            radius: radii,
            color: colors,
        };
        let mut g = Geometry::from_balls(balls, bonds, opt.stick_radius);
        g.show_balls = opt.style != Style::Licorice;
        g.capped = opt.style == Style::Licorice;
        if let Some(cell) = &opt.cell {
            if opt.periodic_bonds {
                split_periodic_sticks(&mut g, cell);
            }
            if opt.draw_cell {
                add_cell_edges(&mut g, cell, CELL_COLOR);
            }
        }
        let mut m = Model::from_geometry(g, watch)?;
        m.color_range = color_range;
        Ok(m)
    }

    /// Builds the BVH and colour tables for ready-made geometry (colours from
    /// `g.balls.color`, grey where missing). `watch`, if given, counts the primitives the BVH
    /// builder has placed in finished subtrees (up to `g.prim_count()`), for a progress
    /// display that reads it from another thread, and can stop the build
    /// ([`Bvh::build_watched`]; never cancelled without a watch).
    pub fn from_geometry(g: Geometry, watch: Option<&Watch>) -> Result<Model, Cancelled> {
        let bvh = Bvh::build_watched(&g, &BuildOptions::default(), watch)?;
        let color = |end: u32| -> i32 {
            g.endpoint_color(end)
                .unwrap_or(crate::rgba(200, 200, 200, 255)) as i32
        };
        let (slot_color_a, slot_color_b): (Vec<i32>, Vec<i32>) = bvh
            .prim_ids
            .par_iter()
            .with_min_len(4096)
            .map(|&id| match g.prim(id) {
                Prim::Ball(i) => (color(i), color(i)),
                Prim::Stick(j) => (color(g.sticks.a[j as usize]), color(g.sticks.b[j as usize])),
            })
            .unzip();
        // Bounding sphere: centre of the box, radius to the farthest ball surface (tighter than
        // the box's half diagonal, so the far view is filled as well as it can be).
        let b = bvh.bounds;
        let (center, radius) = if b.is_empty() {
            ([0.0; 3], 1.0)
        } else {
            let c = b.center();
            let extra = g.sticks.radius.max(0.0);
            let r = (0..g.balls.len())
                .into_par_iter()
                .with_min_len(4096)
                .map(|i| {
                    let d = [
                        (g.balls.x[i] - c[0]) as f64,
                        (g.balls.y[i] - c[1]) as f64,
                        (g.balls.z[i] - c[2]) as f64,
                    ];
                    let rb = if g.show_balls {
                        g.balls.radius[i].max(extra)
                    } else {
                        extra
                    };
                    let v = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() + rb as f64;
                    if v.is_finite() {
                        v
                    } else {
                        0.0
                    }
                })
                .reduce(|| 0.0, f64::max);
            // Extra stick ends (half-sticks, cell corners) count with the stick radius.
            let r_ends = g.sticks.ends.iter().fold(0.0f64, |acc, p| {
                let d2: f64 = (0..3).map(|k| ((p[k] - c[k]) as f64).powi(2)).sum();
                let v = d2.sqrt() + extra as f64;
                if v.is_finite() {
                    acc.max(v)
                } else {
                    acc
                }
            });
            (c, (r.max(r_ends) as f32).max(1e-3))
        };
        Ok(Model {
            geometry: g,
            bvh,
            slot_color_a,
            slot_color_b,
            center,
            radius,
            color_range: None,
            wide: OnceLock::new(),
        })
    }

    /// The 8-wide BVH of secondary rays ((`render::SecondaryTraversal::Wide`)), built from
    /// `bvh` the first time it is asked for (a few ms per million primitives).
    pub fn wide(&self) -> &WideBvh {
        self.wide.get_or_init(|| WideBvh::new(&self.bvh))
    }
}
