//! What `bnsview info` says about a frame: the atoms (counts per element, bounds, cell), the
//! bonds, what loading took, and for each `render` mode the peak memory it would need
//! ([`MemoryEstimate`], the figure the build's refusal uses), as text or JSON.

use molecule::elements;

use crate::input::LoadedFrame;
use crate::memory::MemoryEstimate;
use crate::settings::{BondSettings, ModelSettings, SceneSettings, VolumeSettings};
use crate::SceneError;

/// The frame `render` would draw, for the estimates: size in pixels and u8 volume resolution.
#[derive(Clone, Copy, Debug)]
pub struct EstimateFor {
    /// Frame width and height (pixels).
    pub size: (u32, u32),
    /// Voxels per Å of the density volume.
    pub voxels_per_angstrom: f32,
}

/// A frame described for `bnsview info`.
#[derive(Clone, Debug)]
pub struct Description<'a> {
    /// The frame, with its bonds.
    pub frame: &'a LoadedFrame,
    /// How the bonds were made.
    pub bond_settings: &'a BondSettings,
    /// What the estimates assume.
    pub target: EstimateFor,
    /// Per `render` mode (`bs`, `volume`, `vol+bs`, `path`), the estimate `render` checks
    /// before allocating; the volume modes only when there are atoms.
    pub modes: Vec<(&'static str, MemoryEstimate)>,
}

impl<'a> Description<'a> {
    /// Estimates every mode for `frame` (bonded with `bond_settings`) at `target` (default
    /// model and volume settings). Errors: the density grid cannot be laid out.
    pub fn new(
        frame: &'a LoadedFrame,
        bond_settings: &'a BondSettings,
        target: EstimateFor,
    ) -> Result<Self, SceneError> {
        let model = |wide_bvh| {
            Some(ModelSettings {
                wide_bvh,
                ..Default::default()
            })
        };
        let volume = Some(VolumeSettings {
            voxels_per_angstrom: target.voxels_per_angstrom,
            ..Default::default()
        });
        let mut modes = vec![("bs", model(false), None), ("path", model(true), None)];
        if !frame.molecule.is_empty() {
            modes.insert(1, ("volume", None, volume.clone()));
            modes.insert(2, ("vol+bs", model(false), volume));
        }
        let modes = modes
            .into_iter()
            .map(|(name, model, volume)| {
                let settings = SceneSettings {
                    model,
                    volume,
                    bonds: bond_settings.clone(),
                    frame: Some(target.size),
                    ..Default::default()
                };
                let e = MemoryEstimate::new(&frame.molecule, frame.bonds.len(), &settings)?;
                Ok((name, e))
            })
            .collect::<Result<_, SceneError>>()?;
        Ok(Description {
            frame,
            bond_settings,
            target,
            modes,
        })
    }

    /// The breakdown shown: the largest mode at rest (vol+bs, or bs without atoms).
    fn largest(&self) -> &MemoryEstimate {
        let m = self.modes.iter().find(|(n, _)| *n == "vol+bs");
        &m.unwrap_or(&self.modes[0]).1
    }

    /// Atoms per element symbol, in element order.
    fn element_counts(&self) -> Vec<(&'static str, usize)> {
        let m = &self.frame.molecule;
        let counts = m.element_counts().into_iter();
        counts
            .map(|(z, c)| (elements::element(z).symbol, c))
            .collect()
    }

    /// Bonds per atom (0 without atoms).
    fn bonds_per_atom(&self) -> f64 {
        let n = self.frame.molecule.len();
        if n == 0 {
            0.0
        } else {
            self.frame.bonds.len() as f64 / n as f64
        }
    }

    /// The description as one JSON object (what `info --json` prints).
    pub fn json(&self) -> serde_json::Value {
        use serde_json::{json, Map, Value};
        let (f, m, est) = (self.frame, &self.frame.molecule, self.largest());
        let (lo, hi) = m.bounds();
        let elements: Map<String, Value> = (self.element_counts().into_iter())
            .map(|(s, c)| (s.to_string(), json!(c)))
            .collect();
        let peaks: Map<String, Value> = (self.modes.iter())
            .map(|(n, e)| {
                let pk = &e.peak;
                let v = json!({
                    "bytes": e.peak_bytes(), "phase": pk.phase.name(), "live": pk.live,
                    "retained": pk.retained, "baseline": pk.baseline, "at_rest": e.total(),
                });
                (n.to_string(), v)
            })
            .collect();
        let mut memory: Map<String, Value> = (est.components().iter())
            .map(|(k, b)| (k.to_string(), json!(b)))
            .collect();
        memory.insert("total".into(), json!(est.total()));
        memory.insert("peak".into(), json!(est.peak_bytes()));
        memory.insert(
            "volume_dims".into(),
            json!(est.volume_dims.unwrap_or([0; 3])),
        );
        let vpa = self.target.voxels_per_angstrom;
        memory.insert("voxels_per_angstrom".into(), json!(vpa));
        memory.insert(
            "volume_particles".into(),
            json!(volume::Particles::estimate_bytes(m.len() as u64)),
        );
        json!({
            "source": f.source,
            "format": f.format.map(|f| f.name()),
            "file_bytes": f.file_bytes,
            "frame": f.frame,
            "frames": f.frames,
            "atoms": m.len(),
            "elements": elements,
            "bounds": { "min": lo, "max": hi },
            "cell": m.cell.map(|c| json!({"origin": c.origin, "edges": c.edges, "pbc": c.pbc})),
            "file_bonds": m.file_bonds.as_ref().map(Vec::len),
            "bonds": f.bonds.len(),
            "bonds_per_atom": self.bonds_per_atom(),
            "bond_source": format!("{:?}", self.bond_settings.source).to_lowercase(),
            "pbc": self.bond_settings.options.pbc,
            "unwrap": f.unwrap.map(|u| json!({
                "method": format!("{:?}", u.method).to_lowercase(),
                "crossing_bonds": u.crossing,
            })),
            "load_seconds": f.load_s,
            "bond_seconds": f.bond_s,
            "molecule_bytes": m.memory_bytes(),
            "peak_rss_estimate": peaks,
            "memory_estimate": memory,
            "warnings": f.warnings,
        })
    }

    /// The description as aligned text lines (what `info` prints).
    pub fn text(&self) -> String {
        let (f, m) = (self.frame, &self.frame.molecule);
        let mut out = String::new();
        let mut line = |s: String| {
            out.push_str(&s);
            out.push('\n');
        };
        let mb = |b: u64| b as f64 / 1e6;
        line(format!("source:    {}", f.source));
        if let Some(fmt) = f.format {
            line(format!("format:    {fmt}"));
        }
        line(format!(
            "frames:    {} (showing frame {})",
            f.frames.map_or("not counted".into(), |n| n.to_string()),
            f.frame
        ));
        line(format!("atoms:     {}", m.len()));
        let el: Vec<String> = (self.element_counts().iter())
            .map(|(s, c)| format!("{s} {c}"))
            .collect();
        line(format!("elements:  {}", el.join(", ")));
        let (lo, hi) = m.bounds();
        line(format!(
            "bounds:    [{:.3}, {:.3}, {:.3}] .. [{:.3}, {:.3}, {:.3}] Å",
            lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]
        ));
        if let Some(c) = &m.cell {
            let [a, b, cc] = c.edges;
            let o = c.origin;
            line(format!(
                "cell:      origin {o:?}, a {a:?}, b {b:?}, c {cc:?}"
            ));
        }
        if let Some(fb) = &m.file_bonds {
            line(format!("file bonds: {}", fb.len()));
        }
        let pbc = if self.bond_settings.options.pbc {
            ", pbc"
        } else {
            ""
        };
        line(format!(
            "bonds:     {} ({:.3} per atom, {:?}{pbc}) built in {:.3} s",
            f.bonds.len(),
            self.bonds_per_atom(),
            self.bond_settings.source,
            f.bond_s
        ));
        if let Some(u) = &f.unwrap {
            line(u.describe().replacen("unwrap:  ", "unwrap:    ", 1));
        }
        match f.file_bytes {
            Some(b) => line(format!(
                "load:      {:.3} s ({:.1} MB file)",
                f.load_s,
                mb(b)
            )),
            None => line(format!("load:      {:.3} s", f.load_s)),
        }
        line(format!(
            "molecule:  {:.1} MB in memory",
            mb(m.memory_bytes() as u64)
        ));
        let ((w, h), vpa) = (self.target.size, self.target.voxels_per_angstrom);
        line(format!(
            "memory:    estimated peak RSS of `render --size {w}x{h}` (u8 volume at {vpa} /Å):"
        ));
        for (name, e) in &self.modes {
            let pk = &e.peak;
            line(format!(
                "  {name:<12} {:>10.1} MB  ({}: {:.1} MB alive + {:.1} MB kept by the allocator + {:.1} MB baseline)",
                mb(e.peak_bytes()),
                pk.phase.name(),
                mb(pk.live),
                mb(pk.retained),
                mb(pk.baseline)
            ));
        }
        let est = self.largest();
        line(format!("  at rest (vol+bs), {:.1} MB:", mb(est.total())));
        for (name, bytes) in est.components() {
            // Bytes per atom for what grows with the atoms (#19's measure), not the frame.
            let per_atom = match (name, m.len()) {
                ("framebuffer", _) | (_, 0) => String::new(),
                (_, n) => format!("  ({:.1} B/atom)", bytes as f64 / n as f64),
            };
            if bytes > 0 {
                line(format!("    {name:<12} {:>10.1} MB{per_atom}", mb(bytes)));
            }
        }
        let d = est.volume_dims.unwrap_or([0; 3]);
        line(format!(
            "volume:    {}x{}x{} lattice points at {vpa} /Å: {:.1} MB as u8, {:.1} MB as f32; \
             grid-free (--volume particles) {:.1} MB",
            d[0],
            d[1],
            d[2],
            mb(est.volume),
            mb(est.volume * 4),
            mb(volume::Particles::estimate_bytes(m.len() as u64))
        ));
        out
    }
}
