//! Cameras: pinhole perspective and orthographic, and the paper's far/close views (Table 3).

/// How rays leave the camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Pinhole: all rays from the eye; vertical field of view in degrees.
    Perspective {
        /// Vertical field of view, degrees.
        fov_y_deg: f32,
    },
    /// Parallel rays along the view direction; height of the view in Å.
    Orthographic {
        /// Height of the visible window, Å.
        height: f32,
    },
}

/// The two views of the paper's Table 3.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// The whole bounding sphere fits in the frame.
    Far,
    /// The eye at a quarter of the far distance from the centre (the frame filled).
    Close,
}

/// A camera: eye position and an orthonormal basis (`forward`, `right`, `up`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye (Å); for orthographic cameras the centre of the image plane.
    pub eye: [f32; 3],
    /// Unit view direction.
    pub forward: [f32; 3],
    /// Unit vector to the right of the image.
    pub right: [f32; 3],
    /// Unit vector to the top of the image.
    pub up: [f32; 3],
    /// Projection.
    pub projection: Projection,
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn norm(a: [f64; 3]) -> Option<[f64; 3]> {
    let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    (l > 0.0 && l.is_finite()).then(|| [a[0] / l, a[1] / l, a[2] / l])
}
fn f64x3(a: [f32; 3]) -> [f64; 3] {
    [a[0] as f64, a[1] as f64, a[2] as f64]
}
fn f32x3(a: [f64; 3]) -> [f32; 3] {
    [a[0] as f32, a[1] as f32, a[2] as f32]
}

impl Camera {
    /// Perspective camera at `eye` looking at `at` with `up` roughly upwards, vertical field of
    /// view `fov_y_deg` degrees. A degenerate `up` (parallel to the view) is replaced by
    /// another axis; `eye == at` looks along −z.
    pub fn look_at(eye: [f32; 3], at: [f32; 3], up: [f32; 3], fov_y_deg: f32) -> Camera {
        let (forward, right, up) = basis(f64x3(eye), f64x3(at), f64x3(up));
        Camera {
            eye,
            forward,
            right,
            up,
            projection: Projection::Perspective { fov_y_deg },
        }
    }

    /// Orthographic camera: image plane centred at `eye`, looking at `at`, showing `height` Å
    /// vertically.
    pub fn orthographic(eye: [f32; 3], at: [f32; 3], up: [f32; 3], height: f32) -> Camera {
        let (forward, right, up) = basis(f64x3(eye), f64x3(at), f64x3(up));
        Camera {
            eye,
            forward,
            right,
            up,
            projection: Projection::Orthographic { height },
        }
    }

    /// The paper's views (Table 3) of a bounding sphere (`center`, `radius` in Å), looking
    /// along −z with +y up, vertical field of view `fov_y_deg`, image `aspect` = width/height.
    /// `Far`: the eye at the distance where the whole sphere fits the narrower field of view.
    /// `Close`: the eye at a quarter of that distance from the centre.
    pub fn view(view: View, center: [f32; 3], radius: f32, fov_y_deg: f32, aspect: f32) -> Camera {
        let half_y = (fov_y_deg as f64).to_radians() * 0.5;
        let half_x = (half_y.tan() * aspect.max(1e-6) as f64).atan();
        let half = half_y.min(half_x).max(1e-6);
        let far = radius.max(1e-6) as f64 / half.sin();
        let dist = match view {
            View::Far => far,
            View::Close => far * 0.25,
        };
        let c = f64x3(center);
        let eye = [c[0], c[1], c[2] + dist];
        Camera::look_at(f32x3(eye), center, [0.0, 1.0, 0.0], fov_y_deg)
    }
}

fn basis(eye: [f64; 3], at: [f64; 3], up: [f64; 3]) -> ([f32; 3], [f32; 3], [f32; 3]) {
    let f = norm(sub(at, eye)).unwrap_or([0.0, 0.0, -1.0]);
    let r = norm(cross(f, up))
        .or_else(|| norm(cross(f, [0.0, 1.0, 0.0])))
        .or_else(|| norm(cross(f, [1.0, 0.0, 0.0])))
        .unwrap_or([1.0, 0.0, 0.0]);
    let u = cross(r, f);
    (f32x3(f), f32x3(r), f32x3(u))
}
