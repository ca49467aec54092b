//! `--fit all`: a first pass through the frames to be rendered, finding the sphere that holds
//! every frame, so the camera keeps all of them in view (at the cost of reading the file
//! twice).

use molecule::read::Trajectory;
use scene::{ball_sphere, bounding_sphere, SceneSettings, Sphere};

use crate::{FrameRange, SeriesError};

/// The sphere a frame's scene is fitted to, without building the scene (Å): the balls'
/// sphere when there is a model ([`ball_sphere`]), else the atom centres' grown by the
/// density's reach.
fn frame_sphere(m: &molecule::Molecule, settings: &SceneSettings) -> Sphere {
    match &settings.model {
        Some(ms) => ball_sphere(m, ms),
        None => bounding_sphere(m, None),
    }
}

/// The smallest sphere holding the sphere of every frame of `range` in `traj` (read from its
/// current position).
pub(crate) fn sphere_of_frames(
    traj: &mut Trajectory,
    range: &FrameRange,
    settings: &SceneSettings,
) -> Result<Sphere, SeriesError> {
    let mut all: Option<Sphere> = None;
    let mut seen = 0;
    for (k, m) in traj.by_ref().enumerate() {
        if range.end.is_some_and(|e| k >= e) {
            break;
        }
        let m = m?;
        seen = k + 1;
        if range.contains(k) {
            let s = frame_sphere(&m, settings);
            all = Some(all.map_or(s, |a| a.union(s)));
        }
    }
    all.ok_or_else(|| SeriesError::NoFrames {
        range: range.to_string(),
        count: seen,
    })
}
