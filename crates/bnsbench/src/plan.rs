//! Which measurements to run ([`plan`]), each a typed [`Key`] tagged with the tables it
//! belongs to ([`Tables`]).

use molecule::scenes::SceneName;

use crate::mode::{BenchMode, TableSel, ViewSel};

/// A set of the paper's Tables 1, 2 and 3.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Tables(u8);

impl Tables {
    /// No table.
    pub const NONE: Tables = Tables(0);
    /// Table 1 (frame-buffer size).
    pub const T1: Tables = Tables(1);
    /// Table 2 (threads).
    pub const T2: Tables = Tables(2);
    /// Table 3 (scenes × modes × views).
    pub const T3: Tables = Tables(4);

    /// The table with number `n` (1, 2 or 3).
    pub fn number(n: u64) -> Tables {
        match n {
            1 => Tables::T1,
            2 => Tables::T2,
            3 => Tables::T3,
            _ => Tables::NONE,
        }
    }
    /// Whether `t`'s tables are all in this set.
    pub fn contains(self, t: Tables) -> bool {
        self.0 & t.0 == t.0 && t.0 != 0
    }
    /// The table numbers, ascending.
    pub fn list(self) -> Vec<u8> {
        [(Tables::T1, 1), (Tables::T2, 2), (Tables::T3, 3)]
            .into_iter()
            .filter(|(t, _)| self.contains(*t))
            .map(|(_, n)| n)
            .collect()
    }
}

impl std::ops::BitOr for Tables {
    type Output = Tables;
    fn bitor(self, o: Tables) -> Tables {
        Tables(self.0 | o.0)
    }
}

impl std::ops::BitOrAssign for Tables {
    fn bitor_assign(&mut self, o: Tables) {
        self.0 |= o.0;
    }
}

/// One measurement: a scene's frame of a mode, view, size (pixels) and thread count.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Key {
    /// The scene.
    pub scene: SceneName,
    /// What the frame shows.
    pub mode: BenchMode,
    /// The `far` view, else `close`.
    pub far: bool,
    /// Frame width (pixels).
    pub w: u32,
    /// Frame height (pixels).
    pub h: u32,
    /// Rayon threads.
    pub threads: u32,
}

impl Key {
    /// `far` or `close`.
    pub fn view(&self) -> &'static str {
        if self.far {
            "far"
        } else {
            "close"
        }
    }
}

/// What the user asked to measure; `None` fields take the paper's (or `--quick`'s) defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanSpec {
    /// Which of the paper's tables.
    pub table: TableSel,
    /// Scenes (default all five).
    pub scenes: Option<Vec<SceneName>>,
    /// Modes of Table 3 (default [`BenchMode::PAPER`], quick [`BenchMode::QUICK`]).
    pub modes: Option<Vec<BenchMode>>,
    /// Views of Table 3 (default far, close).
    pub views: Option<Vec<ViewSel>>,
    /// Frame size of Tables 2 and 3 (pixels; default 1024², quick 512²).
    pub size: Option<(u32, u32)>,
    /// Frame sizes of Table 1 (pixels; default 256² … 4096², quick 256² and 512²).
    pub sizes: Option<Vec<(u32, u32)>>,
    /// Thread counts (Table 2 default 1 … nproc, Tables 1 and 3 nproc).
    pub threads: Option<Vec<u32>>,
    /// Small scenes and frames.
    pub quick: bool,
    /// Atoms per scene (overrides the paper's count and `quick`).
    pub atoms: Option<usize>,
}

impl Default for PlanSpec {
    fn default() -> Self {
        PlanSpec {
            table: TableSel::All,
            scenes: None,
            modes: None,
            views: None,
            size: None,
            sizes: None,
            threads: None,
            quick: false,
            atoms: None,
        }
    }
}

impl PlanSpec {
    /// Atoms of a scene in this run.
    pub fn scene_atoms(&self, scene: SceneName) -> usize {
        match self.atoms {
            Some(n) => n,
            None if self.quick => scene.default_atoms().min(100_000),
            None => scene.default_atoms(),
        }
    }
}

/// Position of a scene in [`SceneName::ALL`] (the order of the paper's tables).
pub fn sidx(s: SceneName) -> usize {
    SceneName::ALL.iter().position(|x| *x == s).unwrap_or(0)
}

/// What to measure, in order (grouped by scene), and which tables each measurement belongs
/// to, on a machine of `nproc` cores.
pub fn plan(a: &PlanSpec, nproc: u32) -> Vec<(Key, Tables)> {
    let scenes: Vec<SceneName> = match &a.scenes {
        Some(s) => SceneName::ALL
            .into_iter()
            .filter(|x| s.contains(x))
            .collect(),
        None => SceneName::ALL.to_vec(),
    };
    let has_740 = scenes.contains(&SceneName::Ns740k);
    let want = |t: TableSel| a.table == t || a.table == TableSel::All;
    let ns740_scenes: Vec<SceneName> = if has_740 {
        vec![SceneName::Ns740k]
    } else if a.table != TableSel::All {
        scenes.clone()
    } else {
        Vec::new()
    };
    let mut out: Vec<(Key, Tables)> = Vec::new();
    let mut push = |k: Key, t: Tables| match out.iter_mut().find(|(q, _)| *q == k) {
        Some((_, tags)) => *tags |= t,
        None => out.push((k, t)),
    };
    let default_threads = vec![nproc];
    let size = a
        .size
        .unwrap_or(if a.quick { (512, 512) } else { (1024, 1024) });
    let key = |scene, mode, far, (w, h): (u32, u32), threads| Key {
        scene,
        mode,
        far,
        w,
        h,
        threads,
    };
    if want(TableSel::T3) {
        let modes = match &a.modes {
            Some(m) => m.clone(),
            None if a.quick => BenchMode::QUICK.to_vec(),
            None => BenchMode::PAPER.to_vec(),
        };
        let views = (a.views.clone()).unwrap_or_else(|| vec![ViewSel::Far, ViewSel::Close]);
        let threads = a.threads.clone().unwrap_or_else(|| default_threads.clone());
        for &scene in &scenes {
            for &mode in &modes {
                for &view in &views {
                    for &t in &threads {
                        let far = view == ViewSel::Far;
                        push(key(scene, mode, far, size, t), Tables::T3);
                    }
                }
            }
        }
    }
    if want(TableSel::T1) {
        let sizes = a.sizes.clone().unwrap_or_else(|| {
            let max = if a.quick { 512 } else { 4096 };
            [256, 512, 1024, 2048, 4096]
                .into_iter()
                .filter(|&s| s <= max)
                .map(|s| (s, s))
                .collect()
        });
        let threads = a.threads.clone().unwrap_or_else(|| default_threads.clone());
        for &scene in &ns740_scenes {
            for &wh in &sizes {
                for &t in &threads {
                    push(key(scene, BenchMode::Volume, true, wh, t), Tables::T1);
                }
            }
        }
    }
    if want(TableSel::T2) {
        let threads = a.threads.clone().unwrap_or_else(|| (1..=nproc).collect());
        for &scene in &ns740_scenes {
            for &t in &threads {
                push(key(scene, BenchMode::Volume, true, size, t), Tables::T2);
            }
        }
    }
    // Group by scene (preprocess each once), in the order of SceneName::ALL.
    out.sort_by_key(|(k, _)| sidx(k.scene));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_plan_covers_the_three_tables() {
        let p = plan(&PlanSpec::default(), 2);
        // Table 3: 5 scenes × 4 modes × 2 views; Table 1 adds 4 sizes (1024² is shared),
        // Table 2 adds 1 thread (2 threads at 1024² is shared).
        assert_eq!(p.len(), 40 + 4 + 1);
        let shared = p
            .iter()
            .find(|(k, _)| {
                k.scene == SceneName::Ns740k
                    && k.mode == BenchMode::Volume
                    && k.far
                    && k.w == 1024
                    && k.threads == 2
            })
            .unwrap();
        assert_eq!(shared.1, Tables::T1 | Tables::T2 | Tables::T3);
        assert_eq!(shared.1.list(), [1, 2, 3]);
        // Grouped by scene.
        let order: Vec<SceneName> = p.iter().map(|(k, _)| k.scene).collect();
        let mut sorted = order.clone();
        sorted.sort_by_key(|s| sidx(*s));
        assert_eq!(order, sorted);
    }

    #[test]
    fn tables_one_and_two_need_ns740k_unless_asked_for() {
        let nanobowl = Some(vec![SceneName::Nanobowl]);
        let spec = PlanSpec {
            scenes: nanobowl.clone(),
            size: Some((64, 64)),
            ..PlanSpec::default()
        };
        let p = plan(&spec, 2);
        assert_eq!(p.len(), 8);
        assert!(p.iter().all(|(_, t)| *t == Tables::T3));
        let spec = PlanSpec {
            scenes: nanobowl,
            table: TableSel::T1,
            sizes: Some(vec![(32, 32), (64, 48)]),
            ..PlanSpec::default()
        };
        let p = plan(&spec, 2);
        assert_eq!(p.len(), 2);
        assert_eq!((p[1].0.w, p[1].0.h), (64, 48));
        let spec = PlanSpec {
            table: TableSel::T2,
            ..PlanSpec::default()
        };
        let t: Vec<u32> = plan(&spec, 4).iter().map(|(k, _)| k.threads).collect();
        assert_eq!(t, [1, 2, 3, 4]);
    }

    #[test]
    fn default_modes_are_the_papers_and_quick_adds_two_modalities() {
        let modes = |quick: bool, modes: Option<Vec<BenchMode>>| {
            let spec = PlanSpec {
                scenes: Some(vec![SceneName::Nanobowl]),
                views: Some(vec![ViewSel::Far]),
                table: TableSel::T3,
                quick,
                modes,
                ..PlanSpec::default()
            };
            plan(&spec, 2)
                .iter()
                .map(|(k, _)| k.mode)
                .collect::<Vec<_>>()
        };
        assert_eq!(modes(false, None), BenchMode::PAPER);
        assert_eq!(modes(true, None), BenchMode::QUICK);
        assert_eq!(modes(true, Some(vec![BenchMode::Path])), [BenchMode::Path]);
    }

    #[test]
    fn quick_caps_the_atoms_unless_given() {
        let mut s = PlanSpec {
            quick: true,
            ..PlanSpec::default()
        };
        assert_eq!(s.scene_atoms(SceneName::Ns740k), 100_000);
        assert_eq!(
            s.scene_atoms(SceneName::Nanobowl),
            SceneName::Nanobowl.default_atoms().min(100_000)
        );
        s.atoms = Some(7);
        assert_eq!(s.scene_atoms(SceneName::Anp3), 7);
    }
}
