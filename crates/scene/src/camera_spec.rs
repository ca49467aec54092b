//! A camera written as text (`--camera eye=x,y,z:at=x,y,z[:up=x,y,z][:fov=deg][:ortho=h]`),
//! for the command line and for saved views.

use std::str::FromStr;

use crate::camera::{Camera, Projection};
use crate::fit::Orbit;

/// Why a camera spec was refused (messages name the `--camera` flag and the key).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CameraSpecError {
    /// A part is not `key=value`.
    #[error("--camera: {0:?} is not key=value")]
    NotKeyValue(String),
    /// A key other than eye, at, up, fov, ortho.
    #[error("--camera: unknown key {0:?} (expected eye, at, up, fov, ortho)")]
    UnknownKey(String),
    /// A value that is not what its key needs.
    #[error("--camera {key}={value}: expected {expected}")]
    BadValue {
        /// The key.
        key: &'static str,
        /// Its value as given.
        value: String,
        /// What it should be.
        expected: &'static str,
    },
    /// `eye` or `at` is missing.
    #[error("--camera needs {0}=x,y,z")]
    Missing(&'static str),
    /// An `--orbit` that is not `AZ,EL` with the elevation within ±90°.
    #[error("--orbit {0}: expected AZ,EL in degrees, EL from -90 to 90")]
    BadOrbit(String),
    /// `eye` and `at` coincide, so there is no viewing direction.
    #[error("--camera: eye and at are the same point")]
    NoDirection,
}

/// Three finite numbers `x,y,z` (Å), or a [`CameraSpecError::BadValue`].
fn vec3(key: &'static str, v: &str) -> Result<[f32; 3], CameraSpecError> {
    let c: Vec<Option<f32>> = v.split(',').map(|x| x.trim().parse().ok()).collect();
    match c.as_slice() {
        [Some(x), Some(y), Some(z)] if [x, y, z].iter().all(|a| a.is_finite()) => Ok([*x, *y, *z]),
        _ => Err(CameraSpecError::BadValue {
            key,
            value: v.to_string(),
            expected: "three finite numbers x,y,z",
        }),
    }
}

/// A number in the open range `(lo, hi)`, or a [`CameraSpecError::BadValue`].
fn number(
    key: &'static str,
    v: &str,
    lo: f32,
    hi: f32,
    expected: &'static str,
) -> Result<f32, CameraSpecError> {
    v.trim()
        .parse::<f32>()
        .ok()
        .filter(|x| *x > lo && *x < hi)
        .ok_or_else(|| CameraSpecError::BadValue {
            key,
            value: v.to_string(),
            expected,
        })
}

impl FromStr for Camera {
    type Err = CameraSpecError;

    /// `eye=x,y,z:at=x,y,z` (Å) with optional `up=x,y,z` (default +y), `fov=degrees`
    /// (perspective, default 45) or `ortho=height` (orthographic, view height in Å).
    fn from_str(spec: &str) -> Result<Camera, CameraSpecError> {
        let (mut eye, mut at, mut up, mut fov, mut ortho) =
            (None, None, [0.0, 1.0, 0.0], 45.0f32, None);
        for part in spec.split(':').filter(|p| !p.trim().is_empty()) {
            let (k, v) = part
                .split_once('=')
                .ok_or_else(|| CameraSpecError::NotKeyValue(part.to_string()))?;
            match k.trim() {
                "eye" => eye = Some(vec3("eye", v)?),
                "at" => at = Some(vec3("at", v)?),
                "up" => up = vec3("up", v)?,
                "fov" => fov = number("fov", v, 0.0, 180.0, "degrees in (0, 180)")?,
                "ortho" => {
                    ortho = Some(number(
                        "ortho",
                        v,
                        0.0,
                        f32::INFINITY,
                        "a positive height in Å",
                    )?)
                }
                other => return Err(CameraSpecError::UnknownKey(other.to_string())),
            }
        }
        let eye = eye.ok_or(CameraSpecError::Missing("eye"))?;
        let at = at.ok_or(CameraSpecError::Missing("at"))?;
        if eye == at {
            return Err(CameraSpecError::NoDirection);
        }
        Ok(match ortho {
            Some(h) => Camera::orthographic(eye, at, up, h),
            None => Camera::look_at(eye, at, up, fov),
        })
    }
}

impl FromStr for Orbit {
    type Err = CameraSpecError;

    /// `AZ,EL` (degrees; see [`Orbit`]) with zoom 1.
    fn from_str(s: &str) -> Result<Orbit, CameraSpecError> {
        let v: Vec<Option<f32>> = s.split(',').map(|c| c.trim().parse().ok()).collect();
        match v.as_slice() {
            [Some(az), Some(el)] if az.is_finite() && el.abs() <= 90.0 => Ok(Orbit {
                azimuth_deg: *az,
                elevation_deg: *el,
                zoom: 1.0,
            }),
            _ => Err(CameraSpecError::BadOrbit(s.to_string())),
        }
    }
}

impl std::fmt::Display for Camera {
    /// The `--camera` spec of this camera (`at` one unit along the view direction), which
    /// [`Camera::from_str`] reads back to the same camera up to rounding.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // (`+ 0.0` prints −0 as 0.)
        let v = |a: [f32; 3]| format!("{},{},{}", a[0] + 0.0, a[1] + 0.0, a[2] + 0.0);
        let at = core::array::from_fn(|k| self.eye[k] + self.forward[k]);
        write!(f, "eye={}:at={}:up={}", v(self.eye), v(at), v(self.up))?;
        match self.projection {
            Projection::Perspective { fov_y_deg } => write!(f, ":fov={fov_y_deg}"),
            Projection::Orthographic { height } => write!(f, ":ortho={height}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spec_is_the_camera_of_its_constructor() {
        let c: Camera = "eye=0,0,10:at=0,0,0:fov=30".parse().unwrap();
        assert_eq!(
            c,
            Camera::look_at([0.0, 0.0, 10.0], [0.0; 3], [0.0, 1.0, 0.0], 30.0)
        );
        let c: Camera = "eye=1,2,3:at=0,0,0:up=0,0,1:ortho=12.5".parse().unwrap();
        assert_eq!(
            c,
            Camera::orthographic([1.0, 2.0, 3.0], [0.0; 3], [0.0, 0.0, 1.0], 12.5)
        );
    }

    #[test]
    fn a_camera_prints_as_the_spec_that_makes_it() {
        let close = |a: [f32; 3], b: [f32; 3]| (0..3).all(|k| (a[k] - b[k]).abs() < 1e-5);
        for c in [
            Camera::look_at([3.0, -2.0, 40.5], [1.0, 0.5, -2.0], [0.0, 1.0, 0.0], 37.5),
            Camera::orthographic([0.0, 30.0, 22.0], [0.0; 3], [0.0, 1.0, 0.0], 22.0),
            Camera::look_at([0.0, 50.0, 0.0], [0.0; 3], [0.0, 0.0, -1.0], 45.0),
        ] {
            let back: Camera = c.to_string().parse().unwrap();
            assert!(
                close(back.eye, c.eye) && close(back.forward, c.forward),
                "{c}"
            );
            assert!(close(back.right, c.right) && close(back.up, c.up), "{c}");
            assert_eq!(back.projection, c.projection);
        }
    }

    #[test]
    fn bad_specs_say_which_key_and_what_was_expected() {
        let e = |s: &str| s.parse::<Camera>().unwrap_err().to_string();
        assert_eq!(e("at=0,0,0"), "--camera needs eye=x,y,z");
        assert_eq!(
            e("eye=1,1,1:at=1,1,1"),
            "--camera: eye and at are the same point"
        );
        assert!(e("eye=0,0,1:at=0,0,0:fov=180").contains("fov=180: expected degrees"));
        assert!(e("eye=0,0,NaN:at=0,0,0").contains("three finite numbers"));
        assert!(e("eye=0,0,1:at=0,0,0:ortho=-1").contains("positive height"));
        assert!(e("eye=0,0,1:at=0,0,0:zoom=2").contains("unknown key \"zoom\""));
        assert!(e("eye").contains("not key=value"));
    }
}
