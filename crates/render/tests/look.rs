//! `Look`'s policy: what each mode builds and how it is lit, stated case by case.

use render::{Look, Modality, Mode, SecondaryTraversal, DARK_BACKGROUND, WHITE_BACKGROUND};
use volume::{Light, Lighting};

fn built(l: &Look) -> scene::SceneSettings {
    l.scene_settings(Default::default(), (32, 32))
}

#[test]
fn each_mode_builds_what_it_draws() {
    for (mode, model, volume, bg) in [
        (Mode::Bs, true, false, WHITE_BACKGROUND),
        (Mode::Volume, false, true, DARK_BACKGROUND),
        (Mode::VolBs, true, true, DARK_BACKGROUND),
        (Mode::Path, true, false, DARK_BACKGROUND),
    ] {
        let l = Look {
            mode,
            ..Look::default()
        };
        let s = built(&l);
        assert_eq!(
            (s.model.is_some(), s.volume.is_some()),
            (model, volume),
            "{mode:?}"
        );
        assert_eq!(l.background(), bg, "{mode:?}");
        assert_eq!(l.validate(), Ok(()), "{mode:?}");
    }
}

#[test]
fn light_volume_and_wide_bvh_only_when_used() {
    let shadowed = Look {
        mode: Mode::VolBs,
        shadows: true,
        volume_shadows: true,
        ..Look::default()
    };
    assert!(built(&shadowed).volume.unwrap().light_volume.is_some());
    let rays = Look {
        shadow_rays: true,
        ..shadowed.clone()
    };
    assert!(built(&rays).volume.unwrap().light_volume.is_none());
    assert!(!built(&shadowed).model.unwrap().wide_bvh);
    let wide = Look {
        secondary: SecondaryTraversal::Wide,
        ..shadowed
    };
    assert!(built(&wide).model.unwrap().wide_bvh);
    // Headlight b&s never traces secondary rays, whatever the traversal.
    let plain = Look {
        secondary: SecondaryTraversal::Wide,
        ..Look::default()
    };
    assert!(!built(&plain).model.unwrap().wide_bvh);
    // Path bounces go wide by default.
    let path = Look {
        mode: Mode::Path,
        ..Look::default()
    };
    assert!(built(&path).model.unwrap().wide_bvh);
}

#[test]
fn the_lit_volume_uses_a_headlight_unless_a_light_is_given() {
    let lit = Look {
        mode: Mode::Volume,
        lit: true,
        ..Look::default()
    };
    assert_eq!(lit.march_options().lighting, Lighting::Headlight);
    let point = Look {
        light: Some(Light::Point([1.0, 2.0, 3.0])),
        ..lit.clone()
    };
    assert_eq!(
        point.march_options().lighting,
        Lighting::Point([1.0, 2.0, 3.0])
    );
    let shadowed = Look {
        volume_shadows: true,
        ..lit
    };
    let Light::Directional(d) = shadowed.light() else {
        panic!("the default light is directional")
    };
    assert_eq!(shadowed.march_options().lighting, Lighting::Directional(d));
}

#[test]
fn opacity_scales_the_built_transfer_function_only() {
    let l = Look {
        mode: Mode::Volume,
        opacity: 0.5,
        ..Look::default()
    };
    let tf = built(&l).volume.unwrap().tf;
    let base = l.volume.tf.clone();
    assert_eq!(tf, base.clone().scale_opacity(0.5));
    assert_ne!(tf, base);
}

#[test]
fn modalities_and_refusals() {
    let ao = Look {
        ao: Some(4),
        ..Look::default()
    };
    assert_eq!(
        ao.modality(),
        Modality::Ao {
            samples: 4,
            distance: 4.0
        }
    );
    assert!(Look {
        mode: Mode::Path,
        ..ao
    }
    .validate()
    .is_err());
    assert!(Look {
        lit: true,
        ..Look::default()
    }
    .validate()
    .is_err());
    assert!(Look {
        mode: Mode::Volume,
        shadows: true,
        ..Look::default()
    }
    .validate()
    .is_err());
}
