//! Camera fitting, done once for every command: the scene's bounding sphere and a camera on
//! an orbit around its centre at the far/close distance of the paper's Table 3.

use molecule::{elements, Molecule};

use crate::camera::{Camera, View};
use crate::model::Model;
use crate::settings::{ModelSettings, RadiusKind};

/// Padding (Å) of the atom-centre sphere when there is no geometry: about the support of the
/// density around an atom (√2 × 1.4 Å).
pub const ATOM_SPHERE_PAD: f32 = 2.0;

/// A bounding sphere (Å).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre (Å).
    pub center: [f32; 3],
    /// Radius (Å, > 0).
    pub radius: f32,
}

impl Sphere {
    /// The smallest sphere holding both `self` and `o` (Å).
    pub fn union(self, o: Sphere) -> Sphere {
        let d = (0..3)
            .map(|k| ((o.center[k] - self.center[k]) as f64).powi(2))
            .sum::<f64>()
            .sqrt();
        let (r1, r2) = (self.radius as f64, o.radius as f64);
        if d + r2 <= r1 {
            return self;
        }
        if d + r1 <= r2 {
            return o;
        }
        let r = (d + r1 + r2) * 0.5;
        let t = (r - r1) / d;
        Sphere {
            center: core::array::from_fn(|k| {
                (self.center[k] as f64 + (o.center[k] - self.center[k]) as f64 * t) as f32
            }),
            radius: r as f32,
        }
    }
}

/// The sphere every command fits its camera to: the model's ([`Model::center`],
/// [`Model::radius`]: centre of the BVH box, radius to the farthest ball surface) when there is
/// a model, else the atom centres' (centre of their box) grown by [`ATOM_SPHERE_PAD`].
pub fn bounding_sphere(m: &Molecule, model: Option<&Model>) -> Sphere {
    if let Some(md) = model {
        return Sphere {
            center: md.center,
            radius: md.radius,
        };
    }
    let (lo, hi) = m.bounds();
    let c = [
        (lo[0] + hi[0]) * 0.5,
        (lo[1] + hi[1]) * 0.5,
        (lo[2] + hi[2]) * 0.5,
    ];
    let r2 = (0..m.len())
        .map(|i| (m.x[i] - c[0]).powi(2) + (m.y[i] - c[1]).powi(2) + (m.z[i] - c[2]).powi(2))
        .fold(0.0f32, f32::max);
    Sphere {
        center: c,
        radius: r2.sqrt() + ATOM_SPHERE_PAD,
    }
}

/// The sphere [`Model::new`] would give `m` drawn with `ms` (centre of the balls' box, radius
/// to the farthest ball surface, Å), without building the model: a run that renders only the
/// volume still frames the picture as its ball-and-stick runs do (the benchmark's Table 3).
pub fn ball_sphere(m: &Molecule, ms: &ModelSettings) -> Sphere {
    if m.is_empty() {
        return Sphere {
            center: [0.0; 3],
            radius: 1.0,
        };
    }
    let r: Vec<f32> = m
        .elements
        .iter()
        .map(|&z| {
            let e = elements::element(z);
            let base = match ms.radius {
                RadiusKind::Covalent => e.covalent_radius,
                RadiusKind::Vdw => e.vdw_radius,
            };
            (base * ms.radius_scale).max(ms.stick_radius)
        })
        .collect();
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for (i, &ri) in r.iter().enumerate() {
        for (k, c) in [m.x[i], m.y[i], m.z[i]].into_iter().enumerate() {
            lo[k] = lo[k].min(c - ri);
            hi[k] = hi[k].max(c + ri);
        }
    }
    let c: [f32; 3] = core::array::from_fn(|k| (lo[k] + hi[k]) * 0.5);
    let radius = (0..m.len())
        .map(|i| {
            let d = [m.x[i] - c[0], m.y[i] - c[1], m.z[i] - c[2]].map(|v| v as f64);
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() + r[i] as f64
        })
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max) as f32;
    Sphere {
        center: c,
        radius: radius.max(1e-3),
    }
}

/// Where the camera sits on a sphere around the scene centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    /// Rotation about +y (degrees); 0 looks along −z, 90 looks along −x (eye on +x).
    pub azimuth_deg: f32,
    /// Height above the x-z plane (degrees, −90..90); positive looks down.
    pub elevation_deg: f32,
    /// Zoom factor (> 0): the eye distance is divided by it.
    pub zoom: f32,
}

impl Default for Orbit {
    fn default() -> Self {
        Orbit {
            azimuth_deg: 0.0,
            elevation_deg: 0.0,
            zoom: 1.0,
        }
    }
}

/// The named views of `--view`: the paper's far and close (looking along −z), and the far
/// view from the front (+z), the side (+x) or the top (+y).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum ViewPreset {
    /// The whole molecule in the frame, seen from +z (the paper's far view).
    Far,
    /// A quarter of the far distance from the centre, the frame filled (the paper's close view).
    Close,
    /// As far, from +z (x to the right, y up).
    Front,
    /// As far, from +x (−z to the right, y up).
    Side,
    /// As far, from +y, looking down (x to the right, −z up).
    Top,
}

impl ViewPreset {
    /// The distance and the orbit of the preset (zoom 1).
    pub fn view_and_orbit(self) -> (View, Orbit) {
        let orbit = |azimuth_deg, elevation_deg| Orbit {
            azimuth_deg,
            elevation_deg,
            zoom: 1.0,
        };
        match self {
            ViewPreset::Far | ViewPreset::Front => (View::Far, Orbit::default()),
            ViewPreset::Close => (View::Close, Orbit::default()),
            ViewPreset::Side => (View::Far, orbit(90.0, 0.0)),
            ViewPreset::Top => (View::Far, orbit(0.0, 90.0)),
        }
    }
}

impl Camera {
    /// Fits a perspective camera to `sphere`: the [`View`] distance ([`Camera::view`]) divided
    /// by `orbit.zoom`, from direction (azimuth, elevation) around the centre, vertical field
    /// of view `fov_y_deg`, image `aspect` = width/height. `Orbit::default()` is exactly
    /// [`Camera::view`] (eye on +z, +y up).
    pub fn fit(view: View, sphere: Sphere, fov_y_deg: f32, aspect: f32, orbit: Orbit) -> Camera {
        let base = Camera::view(view, sphere.center, sphere.radius, fov_y_deg, aspect);
        if orbit == Orbit::default() {
            return base;
        }
        let c = sphere.center;
        let dist = (0..3)
            .map(|a| (base.eye[a] as f64 - c[a] as f64).powi(2))
            .sum::<f64>()
            .sqrt()
            / orbit.zoom.max(1e-6) as f64;
        let (az, el) = (
            (orbit.azimuth_deg as f64).to_radians(),
            (orbit.elevation_deg as f64).to_radians(),
        );
        let dir = [az.sin() * el.cos(), el.sin(), az.cos() * el.cos()];
        let up = [-az.sin() * el.sin(), el.cos(), -az.cos() * el.sin()];
        let eye = core::array::from_fn(|a| (c[a] as f64 + dir[a] * dist) as f32);
        Camera::look_at(eye, c, up.map(|u| u as f32), fov_y_deg)
    }
}

/// How the camera of a frame or a series is chosen: given, or fitted to the atoms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CameraChoice {
    /// This camera for every frame.
    Fixed(Camera),
    /// Fitted to the sphere holding every frame to be rendered (a first pass through the
    /// file finds it; not possible when following a file).
    FitAll {
        /// Distance preset.
        view: View,
        /// Direction and zoom around the centre.
        orbit: Orbit,
        /// Vertical field of view (degrees).
        fov_deg: f32,
    },
    /// Fitted once, to the first rendered frame's bounding sphere.
    Fit {
        /// Distance preset.
        view: View,
        /// Direction and zoom around the centre.
        orbit: Orbit,
        /// Vertical field of view (degrees).
        fov_deg: f32,
    },
}

impl CameraChoice {
    /// The camera for atoms within `sphere` in an image of `size` pixels: the fixed one, or
    /// the view fitted to `sphere` ([`CameraChoice::FitAll`]: the caller passes the sphere
    /// holding every frame).
    pub fn camera(&self, sphere: Sphere, size: (u32, u32)) -> Camera {
        match *self {
            CameraChoice::Fixed(c) => c,
            CameraChoice::Fit {
                view,
                orbit,
                fov_deg,
            }
            | CameraChoice::FitAll {
                view,
                orbit,
                fov_deg,
            } => Camera::fit(view, sphere, fov_deg, size.0 as f32 / size.1 as f32, orbit),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: [f32; 3], b: [f32; 3]) -> bool {
        (0..3).all(|k| (a[k] - b[k]).abs() < 1e-4)
    }

    #[test]
    fn default_orbit_is_the_plus_z_view_bit_for_bit() {
        let s = Sphere {
            center: [1.5, -2.25, 3.0],
            radius: 17.3,
        };
        for view in [View::Far, View::Close] {
            let a = Camera::fit(view, s, 45.0, 1.5, Orbit::default());
            let b = Camera::view(view, s.center, s.radius, 45.0, 1.5);
            assert_eq!(a, b);
            assert!(a.eye[2] > s.center[2]);
        }
    }

    #[test]
    fn orbit_moves_the_eye_around_the_centre() {
        let s = Sphere {
            center: [0.0, 0.0, 0.0],
            radius: 10.0,
        };
        let far = Camera::view(View::Far, s.center, s.radius, 45.0, 1.0);
        let d = far.eye[2];
        // Azimuth 90: eye on +x looking along -x.
        let o = Orbit {
            azimuth_deg: 90.0,
            ..Orbit::default()
        };
        let c = Camera::fit(View::Far, s, 45.0, 1.0, o);
        assert!(close(c.eye, [d, 0.0, 0.0]), "{:?}", c.eye);
        assert!(close(c.forward, [-1.0, 0.0, 0.0]));
        assert!(close(c.up, [0.0, 1.0, 0.0]));
        // Elevation 90: eye above, looking down; zoom 2 halves the distance.
        let o = Orbit {
            elevation_deg: 90.0,
            zoom: 2.0,
            ..Orbit::default()
        };
        let c = Camera::fit(View::Far, s, 45.0, 1.0, o);
        assert!(close(c.eye, [0.0, d / 2.0, 0.0]), "{:?}", c.eye);
        assert!(close(c.forward, [0.0, -1.0, 0.0]));
        assert!(close(c.up, [0.0, 0.0, -1.0]), "{:?}", c.up);
    }

    #[test]
    fn presets_look_from_their_side() {
        let s = Sphere {
            center: [1.0, 2.0, 3.0],
            radius: 10.0,
        };
        let cam = |p: ViewPreset| {
            let (v, o) = p.view_and_orbit();
            Camera::fit(v, s, 45.0, 1.0, o)
        };
        assert_eq!(cam(ViewPreset::Front), cam(ViewPreset::Far));
        assert!(close(cam(ViewPreset::Side).forward, [-1.0, 0.0, 0.0]));
        assert!(close(cam(ViewPreset::Top).forward, [0.0, -1.0, 0.0]));
        assert!(close(cam(ViewPreset::Top).right, [1.0, 0.0, 0.0]));
        for p in [ViewPreset::Side, ViewPreset::Top] {
            let d = |c: Camera| {
                (0..3)
                    .map(|k| (c.eye[k] - s.center[k]).powi(2))
                    .sum::<f32>()
            };
            assert!((d(cam(p)) - d(cam(ViewPreset::Far))).abs() < 1e-2, "{p:?}");
        }
    }

    #[test]
    fn atom_sphere_contains_every_atom_with_the_pad() {
        let mut m = Molecule::with_capacity(3);
        m.push([0.0, 0.0, 0.0], 6);
        m.push([4.0, 0.0, 0.0], 6);
        m.push([2.0, 3.0, -1.0], 8);
        let s = bounding_sphere(&m, None);
        assert_eq!(s.center, [2.0, 1.5, -0.5]);
        for i in 0..m.len() {
            let p = m.position(i);
            let d = (0..3)
                .map(|k| (p[k] - s.center[k]).powi(2))
                .sum::<f32>()
                .sqrt();
            assert!(d + ATOM_SPHERE_PAD <= s.radius + 1e-5);
        }
    }
}
