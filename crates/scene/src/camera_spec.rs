//! A camera written as text (`--camera eye=x,y,z:at=x,y,z[:up=x,y,z][:fov=deg][:ortho=h]`),
//! for the command line and for saved views.

use std::str::FromStr;

use crate::camera::Camera;

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
