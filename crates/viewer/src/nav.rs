//! Turntable navigation of the viewer: the eye on a sphere around a centre, moved by orbit
//! (azimuth about +y, elevation), pan (the centre in the image plane) and zoom (the distance).
//! Pure functions of the state, so the maths is tested without a window.

use scene::{Camera, Projection, Sphere};

/// Where the viewer's camera is: a turntable around `center`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Navigation {
    /// The point looked at and orbited around (Å).
    pub center: [f64; 3],
    /// Eye distance from the centre (Å).
    pub distance: f64,
    /// Rotation of the eye about +y (degrees); 0 puts the eye on +z.
    pub azimuth_deg: f64,
    /// Height of the eye above the x-z plane (degrees); any value, the view turns over the pole.
    pub elevation_deg: f64,
    /// Perspective: vertical field of view (degrees); orthographic: view height (Å).
    pub projection: Projection,
}

impl Navigation {
    /// The turntable that sees what `camera` sees, orbiting around the point of its view ray
    /// nearest `sphere`'s centre (a camera rolled about its view axis comes back upright).
    pub fn from_camera(camera: &Camera, sphere: Sphere) -> Navigation {
        let f = camera.forward.map(f64::from);
        let eye = camera.eye.map(f64::from);
        let to_c: f64 = (0..3)
            .map(|k| (sphere.center[k] as f64 - eye[k]) * f[k])
            .sum();
        let distance = if to_c > 1e-6 {
            to_c
        } else {
            sphere.radius.max(1e-3) as f64
        };
        let center = core::array::from_fn(|k| eye[k] + f[k] * distance);
        // The direction from the centre to the eye is −forward.
        let elevation_deg = (-f[1]).clamp(-1.0, 1.0).asin().to_degrees();
        let azimuth_deg = (-f[0]).atan2(-f[2]).to_degrees();
        Navigation {
            center,
            distance,
            azimuth_deg,
            elevation_deg,
            projection: camera.projection,
        }
    }

    /// Turns the eye about the centre by `d_azimuth` degrees about +y and raises it by
    /// `d_elevation` degrees.
    pub fn orbit(self, d_azimuth: f64, d_elevation: f64) -> Navigation {
        Navigation {
            azimuth_deg: (self.azimuth_deg + d_azimuth) % 360.0,
            elevation_deg: (self.elevation_deg + d_elevation) % 360.0,
            ..self
        }
    }

    /// Moves the centre (and the eye with it) by `dx`, `dy` pixels of an image `height`
    /// pixels high, so that the point at the centre follows the mouse: right and up on screen
    /// for positive values.
    pub fn pan(self, dx: f64, dy: f64, height: u32) -> Navigation {
        let (_, right, up) = self.frame();
        let k = self.view_height() / height.max(1) as f64;
        let center = core::array::from_fn(|a| self.center[a] - (right[a] * dx - up[a] * dy) * k);
        Navigation { center, ..self }
    }

    /// Brings the eye `factor` times closer to the centre (an orthographic view shows `factor`
    /// times less); the centre and the view direction stay.
    pub fn zoom(self, factor: f64) -> Navigation {
        let f = if factor.is_finite() && factor > 0.0 {
            factor
        } else {
            1.0
        };
        match self.projection {
            Projection::Perspective { .. } => Navigation {
                distance: (self.distance / f).max(1e-4),
                ..self
            },
            Projection::Orthographic { height } => Navigation {
                projection: Projection::Orthographic {
                    height: (height as f64 / f).max(1e-4) as f32,
                },
                ..self
            },
        }
    }

    /// Height of the view at the centre (Å).
    fn view_height(&self) -> f64 {
        match self.projection {
            Projection::Perspective { fov_y_deg } => {
                2.0 * self.distance * ((fov_y_deg as f64).to_radians() * 0.5).tan()
            }
            Projection::Orthographic { height } => height as f64,
        }
    }

    /// (unit direction from the centre to the eye, right, up) of the turntable.
    fn frame(&self) -> ([f64; 3], [f64; 3], [f64; 3]) {
        let (az, el) = (
            self.azimuth_deg.to_radians(),
            self.elevation_deg.to_radians(),
        );
        let dir = [az.sin() * el.cos(), el.sin(), az.cos() * el.cos()];
        let up = [-az.sin() * el.sin(), el.cos(), -az.cos() * el.sin()];
        let right = [az.cos(), 0.0, -az.sin()];
        (dir, right, up)
    }

    /// Eye, centre and up as the `f32` values the camera is made of.
    fn points(&self) -> ([f32; 3], [f32; 3], [f32; 3]) {
        let (dir, _, up) = self.frame();
        let eye = core::array::from_fn(|a| (self.center[a] + dir[a] * self.distance) as f32);
        (eye, self.center.map(|c| c as f32), up.map(|u| u as f32))
    }

    /// The `--camera` string of this view: `bnsview render --camera` with it renders exactly
    /// [`Navigation::camera`].
    pub fn spec(&self) -> String {
        let (eye, at, up) = self.points();
        let v = |a: [f32; 3]| format!("{},{},{}", a[0] + 0.0, a[1] + 0.0, a[2] + 0.0);
        let proj = match self.projection {
            Projection::Perspective { fov_y_deg } => format!("fov={fov_y_deg}"),
            Projection::Orthographic { height } => format!("ortho={height}"),
        };
        format!("eye={}:at={}:up={}:{proj}", v(eye), v(at), v(up))
    }

    /// The camera of this view (what [`Navigation::spec`] parses to).
    pub fn camera(&self) -> Camera {
        let (eye, at, up) = self.points();
        match self.projection {
            Projection::Perspective { fov_y_deg } => Camera::look_at(eye, at, up, fov_y_deg),
            Projection::Orthographic { height } => Camera::orthographic(eye, at, up, height),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use scene::{Orbit, View};

    fn sphere() -> Sphere {
        Sphere {
            center: [3.0, -1.5, 7.25],
            radius: 12.0,
        }
    }

    fn start() -> Navigation {
        let cam = Camera::fit(View::Far, sphere(), 45.0, 1.0, Orbit::default());
        Navigation::from_camera(&cam, sphere())
    }

    fn close(a: [f32; 3], b: [f32; 3], tol: f32) -> bool {
        (0..3).all(|k| (a[k] - b[k]).abs() <= tol)
    }

    /// Orbit, pan and zoom magnitudes drawn on a log scale, with both signs.
    fn log_scale(n: usize) -> Vec<f64> {
        (0..n)
            .map(|i| {
                let v = 10f64.powf(-2.0 + 4.0 * i as f64 / (n - 1) as f64);
                if i % 2 == 0 {
                    v
                } else {
                    -v
                }
            })
            .collect()
    }

    #[test]
    fn a_fitted_camera_is_seen_as_it_was() {
        let cam = Camera::fit(View::Far, sphere(), 45.0, 1.0, Orbit::default());
        let n = Navigation::from_camera(&cam, sphere());
        let c = n.camera();
        assert!(close(c.eye, cam.eye, 1e-4) && close(c.forward, cam.forward, 1e-6));
        assert!(close(c.up, cam.up, 1e-6));
        assert!(close(n.center.map(|v| v as f32), sphere().center, 1e-4));
        for (az, el) in [(90.0, 0.0), (-30.0, 45.0), (170.0, -60.0)] {
            let o = Orbit {
                azimuth_deg: az,
                elevation_deg: el,
                zoom: 1.0,
            };
            let cam = Camera::fit(View::Far, sphere(), 45.0, 1.0, o);
            let c = Navigation::from_camera(&cam, sphere()).camera();
            assert!(close(c.eye, cam.eye, 1e-3), "{az} {el}: {c:?} vs {cam:?}");
            assert!(close(c.up, cam.up, 1e-5), "{az} {el}");
        }
    }

    #[test]
    fn the_spec_parses_to_the_camera_bit_for_bit() {
        let mut n = start();
        for (i, v) in log_scale(12).into_iter().enumerate() {
            n = match i % 3 {
                0 => n.orbit(v * 7.0, v),
                1 => n.pan(v * 13.0, -v * 5.0, 600),
                _ => n.zoom(1.0 + v.abs().min(5.0) * 0.1),
            };
            let parsed: Camera = n.spec().parse().unwrap();
            assert_eq!(parsed, n.camera(), "{}", n.spec());
        }
    }

    #[test]
    fn orbiting_a_full_turn_returns_to_the_start() {
        let n0 = start();
        for step in [1.0, 7.5, 10.0, 45.0, 120.0] {
            let mut n = n0;
            let turns = (360.0 / step) as usize;
            for _ in 0..turns {
                n = n.orbit(step, 0.0);
            }
            assert!(
                close(n.camera().eye, n0.camera().eye, 1e-3),
                "azimuth {step}"
            );
            let mut n = n0;
            for _ in 0..turns {
                n = n.orbit(0.0, step);
            }
            let (a, b) = (n.camera(), n0.camera());
            assert!(close(a.eye, b.eye, 1e-3), "elevation {step}: {a:?} {b:?}");
            assert!(close(a.up, b.up, 1e-5), "elevation {step}");
        }
    }

    #[test]
    fn orbit_keeps_the_centre_and_the_distance() {
        let n0 = start();
        for v in log_scale(9) {
            let n = n0.orbit(v * 3.0, v);
            let c = n.camera();
            assert_eq!(n.center, n0.center);
            let d: f64 = (0..3)
                .map(|k| (c.eye[k] as f64 - n.center[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            assert!((d - n0.distance).abs() < 1e-3 * n0.distance, "{v}");
            // Still looking at the centre.
            let to_c: [f32; 3] =
                core::array::from_fn(|k| (n.center[k] as f32 - c.eye[k]) / d as f32);
            assert!(close(to_c, c.forward, 1e-4), "{v}");
        }
    }

    #[test]
    fn zoom_keeps_the_centre_and_the_direction() {
        let n0 = start().orbit(33.0, 21.0);
        for f in [1.01, 1.5, 2.0, 10.0, 0.5, 0.1] {
            let n = n0.zoom(f);
            assert_eq!(n.center, n0.center);
            assert!((n.distance - n0.distance / f).abs() < 1e-9 * n0.distance);
            assert!(close(n.camera().forward, n0.camera().forward, 1e-6), "{f}");
            // Zooming back returns.
            assert!(close(n.zoom(1.0 / f).camera().eye, n0.camera().eye, 1e-3));
        }
        // Nonsense factors do nothing.
        for f in [0.0, -2.0, f64::NAN, f64::INFINITY] {
            assert_eq!(n0.zoom(f), n0);
        }
    }

    #[test]
    fn pan_moves_the_centre_in_the_image_plane_and_back() {
        let n0 = start().orbit(-40.0, 15.0);
        let c0 = n0.camera();
        for v in log_scale(8) {
            let n = n0.pan(v * 10.0, v * 4.0, 512);
            let moved: [f64; 3] = core::array::from_fn(|k| n.center[k] - n0.center[k]);
            // Perpendicular to the view: the distance and direction stay.
            let along: f64 = (0..3).map(|k| moved[k] * c0.forward[k] as f64).sum();
            assert!(along.abs() < 1e-6 * n0.distance, "{v}");
            assert!(close(n.camera().forward, c0.forward, 1e-6));
            // Dragging right moves the centre left (the scene follows the mouse).
            let right: f64 = (0..3).map(|k| moved[k] * c0.right[k] as f64).sum();
            assert!(right * v < 0.0, "{v}: {right}");
            let back = n.pan(-v * 10.0, -v * 4.0, 512);
            assert!(close(back.camera().eye, c0.eye, 1e-3));
        }
        // A pan by the image height moves the centre by the view height at the centre.
        let n = n0.pan(0.0, 512.0, 512);
        let d: f64 = (0..3)
            .map(|k| (n.center[k] - n0.center[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        let h = 2.0 * n0.distance * (22.5f64).to_radians().tan();
        assert!((d - h).abs() < 1e-6 * h, "{d} vs {h}");
    }

    #[test]
    fn orthographic_views_zoom_their_height() {
        let cam = Camera::orthographic([0.0, 0.0, 20.0], [0.0; 3], [0.0, 1.0, 0.0], 30.0);
        let n = Navigation::from_camera(&cam, sphere());
        let z = n.zoom(2.0);
        assert_eq!(z.projection, Projection::Orthographic { height: 15.0 });
        assert_eq!(z.distance, n.distance);
        let parsed: Camera = z.spec().parse().unwrap();
        assert_eq!(parsed, z.camera());
    }
}
