//! What a benchmark frame shows ([`BenchMode`]), named sets of modes ([`ModeSel`]) and which
//! of the paper's tables to reproduce ([`TableSel`]).

use std::str::FromStr;

use render::{Look, Material, Mode, RenderSettings};

/// What a benchmark frame shows: the rows of the paper's Table 3, lit volume alone, and the
/// ray tracing modalities of §4.5 / Figure 4 (one sample per pixel per frame).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum BenchMode {
    /// Ball-and-stick, headlight diffuse shading ("b&s").
    Bs,
    /// Unlit volume rendering alone ("volume").
    Volume,
    /// Ball-and-stick, then the unlit volume in front of it ("vol+b&s").
    #[cfg_attr(feature = "clap", value(name = "vol+bs"))]
    VolBs,
    /// As vol+bs with gradient lighting of the volume ("vol+b&s, lit").
    #[cfg_attr(feature = "clap", value(name = "vol+bs-lit"))]
    VolBsLit,
    /// Volume alone with gradient lighting (not a row of Table 3).
    #[cfg_attr(feature = "clap", value(name = "volume-lit"))]
    VolumeLit,
    /// Ball-and-stick, diffuse light with hard shadows (`bnsview render --shadows`).
    #[cfg_attr(feature = "clap", value(name = "bs-shadows"))]
    BsShadows,
    /// Ball-and-stick, ambient occlusion with 1 ray per pixel (fps per AO sample; `--ao N`
    /// costs about N times as much).
    #[cfg_attr(feature = "clap", value(name = "bs-ao"))]
    BsAo,
    /// Ball-and-stick path traced, metal BRDF, 1 sample per pixel (fps per spp).
    Path,
    /// vol+bs with hard shadows attenuated by the volume, which also shadows itself
    /// (`--volume-shadows`, §4.5).
    #[cfg_attr(feature = "clap", value(name = "vol+bs-shadows"))]
    VolBsShadows,
    /// Unlit volume alone with volumetric shadows (Figure 4, fourth picture).
    #[cfg_attr(feature = "clap", value(name = "volume-shadows"))]
    VolumeShadows,
    /// Gradient-lit volume alone with volumetric shadows (Figure 4, fifth picture).
    #[cfg_attr(feature = "clap", value(name = "volume-lit-shadows"))]
    VolumeLitShadows,
}

impl BenchMode {
    /// Every mode, in the order of `--modes all`.
    pub const ALL: [BenchMode; 11] = [
        BenchMode::Bs,
        BenchMode::Volume,
        BenchMode::VolBs,
        BenchMode::VolBsLit,
        BenchMode::VolumeLit,
        BenchMode::BsShadows,
        BenchMode::BsAo,
        BenchMode::Path,
        BenchMode::VolBsShadows,
        BenchMode::VolumeShadows,
        BenchMode::VolumeLitShadows,
    ];

    /// The four rows of the paper's Table 3, the default.
    pub const PAPER: [BenchMode; 4] = [
        BenchMode::Bs,
        BenchMode::Volume,
        BenchMode::VolBs,
        BenchMode::VolBsLit,
    ];

    /// The default of `--quick`: the paper's four and the two cheap modalities (at 512² they
    /// add ~10 s to a ~70 s quick run; path tracing and the lit volume would add ~3 minutes).
    pub const QUICK: [BenchMode; 6] = [
        BenchMode::Bs,
        BenchMode::Volume,
        BenchMode::VolBs,
        BenchMode::VolBsLit,
        BenchMode::BsShadows,
        BenchMode::BsAo,
    ];

    /// The modalities issue 6 asks figures of (`--modes modalities`).
    pub const MODALITIES: [BenchMode; 7] = [
        BenchMode::BsShadows,
        BenchMode::BsAo,
        BenchMode::Path,
        BenchMode::VolumeLit,
        BenchMode::VolBsLit,
        BenchMode::VolumeShadows,
        BenchMode::VolumeLitShadows,
    ];

    /// Name as on the command line and in the JSON.
    pub fn name(self) -> &'static str {
        match self {
            BenchMode::Bs => "bs",
            BenchMode::Volume => "volume",
            BenchMode::VolBs => "vol+bs",
            BenchMode::VolBsLit => "vol+bs-lit",
            BenchMode::VolumeLit => "volume-lit",
            BenchMode::BsShadows => "bs-shadows",
            BenchMode::BsAo => "bs-ao",
            BenchMode::Path => "path",
            BenchMode::VolBsShadows => "vol+bs-shadows",
            BenchMode::VolumeShadows => "volume-shadows",
            BenchMode::VolumeLitShadows => "volume-lit-shadows",
        }
    }

    /// Whether the frame shows the ball-and-stick geometry (needs the BVH).
    pub fn geometry(self) -> bool {
        self.look().mode.has_model()
    }

    /// Whether the frame shows the density volume (needs the volume).
    pub fn volume(self) -> bool {
        self.look().mode.has_volume()
    }

    /// Row of the paper's Table 3 (CPU), if this mode is one.
    pub fn paper_row(self) -> Option<usize> {
        BenchMode::PAPER.iter().position(|&m| m == self)
    }

    /// What the frame shows: the look of `bnsview render` with the same flags (default
    /// light, AO distance and material) at one sample per pixel (`--ao 1`, `--spp 1`).
    pub fn look(self) -> Look {
        use BenchMode::*;
        let mode = match self {
            Bs | BsShadows | BsAo => Mode::Bs,
            Volume | VolumeLit | VolumeShadows | VolumeLitShadows => Mode::Volume,
            VolBs | VolBsLit | VolBsShadows => Mode::VolBs,
            Path => Mode::Path,
        };
        Look {
            mode,
            lit: matches!(self, VolBsLit | VolumeLit | VolumeLitShadows),
            shadows: matches!(self, BsShadows | VolBsShadows),
            ao: (self == BsAo).then_some(1),
            volume_shadows: matches!(self, VolBsShadows | VolumeShadows | VolumeLitShadows),
            material: Material::Metal,
            spp: 1,
            ..Look::default()
        }
    }

    /// How the frame is shaded ([`BenchMode::look`]'s settings); the volume pass's options
    /// are `settings().march`.
    pub fn settings(self) -> RenderSettings {
        self.look().render_settings()
    }

    /// Random samples per pixel of one frame (AO rays, paths), for the stochastic modes.
    pub fn samples_per_pixel(self) -> Option<u32> {
        match self {
            BenchMode::BsAo | BenchMode::Path => Some(1),
            _ => None,
        }
    }
}

/// A name that is no [`BenchMode`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown bench mode {0:?}")]
pub struct UnknownMode(pub String);

impl FromStr for BenchMode {
    type Err = UnknownMode;
    /// The mode of a [`BenchMode::name`], ignoring ASCII case.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        BenchMode::ALL
            .into_iter()
            .find(|m| m.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| UnknownMode(s.to_string()))
    }
}

/// An entry of `--modes`: a mode or a named set of them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModeSel {
    /// One mode.
    One(BenchMode),
    /// Every mode.
    All,
    /// [`BenchMode::MODALITIES`].
    Modalities,
}

#[cfg(feature = "clap")]
impl clap::ValueEnum for ModeSel {
    fn value_variants<'a>() -> &'a [Self] {
        static V: std::sync::OnceLock<Vec<ModeSel>> = std::sync::OnceLock::new();
        V.get_or_init(|| {
            BenchMode::ALL
                .iter()
                .map(|&m| ModeSel::One(m))
                .chain([ModeSel::All, ModeSel::Modalities])
                .collect()
        })
    }
    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        use clap::builder::PossibleValue;
        match self {
            ModeSel::One(m) => m.to_possible_value(),
            ModeSel::All => Some(PossibleValue::new("all").help("Every mode above.")),
            ModeSel::Modalities => Some(PossibleValue::new("modalities").help(
                "bs-shadows, bs-ao, path, volume-lit, vol+bs-lit, volume-shadows, \
                         volume-lit-shadows (issue 6).",
            )),
        }
    }
}

/// The modes of `--modes` in the order given, sets expanded, each once.
pub fn expand_modes(sel: &[ModeSel]) -> Vec<BenchMode> {
    let mut out: Vec<BenchMode> = Vec::new();
    for s in sel {
        let modes: &[BenchMode] = match s {
            ModeSel::One(m) => std::slice::from_ref(m),
            ModeSel::All => &BenchMode::ALL,
            ModeSel::Modalities => &BenchMode::MODALITIES,
        };
        for &m in modes {
            if !out.contains(&m) {
                out.push(m);
            }
        }
    }
    out
}

/// Which of the paper's views (Table 3).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum ViewSel {
    /// The whole molecule fits in the frame.
    Far,
    /// A quarter of the far distance from the centre, the frame filled.
    Close,
}

/// Which of the paper's tables to reproduce.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum TableSel {
    /// Table 1: ns740k, far, volume, frame buffer 256² … 4096².
    #[cfg_attr(feature = "clap", value(name = "1"))]
    T1,
    /// Table 2: ns740k, far, volume, 1024², threads 1 … nproc.
    #[cfg_attr(feature = "clap", value(name = "2"))]
    T2,
    /// Table 3: scenes × modes × far/close at 1024².
    #[cfg_attr(feature = "clap", value(name = "3"))]
    T3,
    /// All three.
    All,
}

#[cfg(test)]
mod tests {
    use super::*;
    use render::Modality;

    #[test]
    fn names_read_back_and_are_distinct() {
        for m in BenchMode::ALL {
            assert_eq!(m.name().parse::<BenchMode>(), Ok(m));
            assert_eq!(m.name().to_uppercase().parse::<BenchMode>(), Ok(m));
        }
        let mut names: Vec<&str> = BenchMode::ALL.iter().map(|m| m.name()).collect();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), BenchMode::ALL.len());
        assert!("shadows".parse::<BenchMode>().is_err());
    }

    #[test]
    fn every_mode_settings_are_valid_for_what_it_draws() {
        for m in BenchMode::ALL {
            let s = m.settings();
            assert_eq!(s.validate(m.geometry(), m.volume()), Ok(()), "{m:?}");
            // The stochastic modes are the ray-traced ones that sample at random.
            let random = matches!(s.modality, Modality::Ao { .. } | Modality::Path { .. });
            assert_eq!(m.samples_per_pixel().is_some(), random, "{m:?}");
            assert_eq!(s.frame_samples(), 1, "{m:?}");
            assert_eq!(
                s.march.shadows.is_some(),
                m.name().contains("shadows") && m.volume()
            );
        }
    }

    #[test]
    fn sets_expand_in_order_each_once() {
        let e = expand_modes(&[
            ModeSel::One(BenchMode::Path),
            ModeSel::Modalities,
            ModeSel::One(BenchMode::Bs),
        ]);
        let names: Vec<&str> = e.iter().map(|m| m.name()).collect();
        assert_eq!(
            names,
            [
                "path",
                "bs-shadows",
                "bs-ao",
                "volume-lit",
                "vol+bs-lit",
                "volume-shadows",
                "volume-lit-shadows",
                "bs"
            ]
        );
        assert_eq!(expand_modes(&[ModeSel::All]), BenchMode::ALL);
    }

    #[cfg(feature = "clap")]
    #[test]
    fn all_lists_the_modes_in_the_clap_order() {
        use clap::ValueEnum;
        assert_eq!(BenchMode::value_variants(), BenchMode::ALL);
        for m in BenchMode::ALL {
            assert_eq!(m.to_possible_value().unwrap().get_name(), m.name());
        }
    }
}
