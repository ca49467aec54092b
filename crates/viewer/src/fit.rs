//! Which built scene serves which settings: a scene may hold more than the toggles ask for
//! (the first time step's holds the model and the volume), and the colour and density ranges
//! of the first step are kept for the others.

use scene::{ColorBy, Scene, SceneSettings};

/// The column colour range and the density at the top of the transfer function of the first
/// time step shown (the density: of the first one shown with a volume).
pub(crate) type Ranges = (Option<(f32, f32)>, Option<f32>);

/// How a built scene serves the settings `need`.
pub(crate) enum Fit {
    /// As it is.
    Serves,
    /// With this transfer function instead of its own.
    NewTf(volume::TransferFunction),
    /// Not: it must be rebuilt.
    Rebuild,
}

/// Whether `scene` can show what `need` asks for (the wide BVH is built on demand, so it does
/// not count; a scene may hold more than asked for).
pub(crate) fn fit(scene: &Scene, need: &SceneSettings) -> Fit {
    fit_settings(&scene.settings, need)
}

/// How a scene built with the settings `have` serves `need` (see [`fit`]).
pub(crate) fn fit_settings(have: &SceneSettings, need: &SceneSettings) -> Fit {
    let model_ok = match (&need.model, &have.model) {
        (None, _) => true,
        (Some(n), Some(h)) => {
            scene::ModelSettings {
                wide_bvh: h.wide_bvh,
                ..n.clone()
            } == *h
        }
        (Some(_), None) => false,
    };
    if !model_ok || need.bonds != have.bonds {
        return Fit::Rebuild;
    }
    match (&need.volume, &have.volume) {
        (None, _) => Fit::Serves,
        (Some(n), Some(h)) if n == h => Fit::Serves,
        (Some(n), Some(h))
            if scene::VolumeSettings {
                tf: h.tf.clone(),
                ..n.clone()
            } == *h =>
        {
            Fit::NewTf(n.tf.clone())
        }
        _ => Fit::Rebuild,
    }
}

/// Fixes the colour and density ranges left open in `s` to the first frame's.
pub(crate) fn fix_ranges(s: &mut SceneSettings, (color, density): Ranges) {
    if let Some(ms) = s.model.as_mut() {
        if let ColorBy::Column { range, .. } = &mut ms.color {
            *range = range.or(color);
        }
    }
    if let Some(vs) = s.volume.as_mut() {
        vs.density_max = vs.density_max.or(density);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use molecule::scenes::{try_generate, SceneName};
    use scene::{ModelSettings, VolumeSettings};
    use spmd::Isa;

    #[test]
    fn a_scene_serves_what_it_holds_and_only_that() {
        let m = try_generate(SceneName::Nanobowl, Some(400), 1).unwrap();
        let both = SceneSettings {
            volume: Some(VolumeSettings {
                voxels_per_angstrom: 1.0,
                ..VolumeSettings::default()
            }),
            ..SceneSettings::default()
        };
        let isa = Isa::detect();
        let mut sc = Scene::build(isa, &m, &both).unwrap();
        let bs = SceneSettings {
            volume: None,
            ..both.clone()
        };
        let volume = SceneSettings {
            model: None,
            ..both.clone()
        };
        assert!(matches!(fit(&sc, &both), Fit::Serves));
        assert!(matches!(fit(&sc, &bs), Fit::Serves));
        assert!(matches!(fit(&sc, &volume), Fit::Serves));
        // The wide BVH is built on demand: it does not call for a rebuild.
        let wide = SceneSettings {
            model: Some(ModelSettings {
                wide_bvh: true,
                ..ModelSettings::default()
            }),
            ..bs.clone()
        };
        assert!(matches!(fit(&sc, &wide), Fit::Serves));
        // Other balls do.
        let fat = SceneSettings {
            model: Some(ModelSettings {
                radius_scale: 0.8,
                ..ModelSettings::default()
            }),
            ..bs.clone()
        };
        assert!(matches!(fit(&sc, &fat), Fit::Rebuild));
        // Another opacity re-classifies the transfer function, as a build with it would.
        let mut opaque = both.clone();
        let vs = opaque.volume.as_mut().unwrap();
        vs.tf = vs.tf.clone().scale_opacity(2.0);
        let Fit::NewTf(tf) = fit(&sc, &opaque) else {
            panic!("expected a new transfer function");
        };
        assert!(sc.set_transfer_function(&tf));
        let built = Scene::build(isa, &m, &opaque).unwrap();
        let (a, b) = (
            &sc.volume.as_ref().unwrap().tf,
            &built.volume.as_ref().unwrap().tf,
        );
        assert_eq!(
            (&a.preint, &a.post, &a.range_max),
            (&b.preint, &b.post, &b.range_max)
        );
        assert!(matches!(fit(&sc, &opaque), Fit::Serves));
        // A scene without a volume serves no volume.
        let only_bs = Scene::build(isa, &m, &bs).unwrap();
        assert!(matches!(fit(&only_bs, &volume), Fit::Rebuild));
    }
}
