//! What the keys do: key names (shared by the window and `--script`'s `key NAME`), the
//! actions they stand for, and the display toggles they change.

use render::{Look, Mode};

/// The next mode of the `v` key: bs → vol+bs → volume → path → bs.
pub fn next_mode(m: Mode) -> Mode {
    match m {
        Mode::Bs => Mode::VolBs,
        Mode::VolBs => Mode::Volume,
        Mode::Volume => Mode::Path,
        Mode::Path => Mode::Bs,
    }
}

/// The display options the keys change; everything else stays as the command line set it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Toggles {
    /// What is drawn.
    pub mode: Mode,
    /// Direct light with hard shadows on the balls and sticks (`--shadows`).
    pub shadows: bool,
    /// Ambient occlusion with this many rays per hit (`--ao N`), when on.
    pub ao: Option<u32>,
    /// Gradient lighting of the volume (`--lit`).
    pub lit: bool,
    /// Factor on every opacity of the transfer function (`--opacity`).
    pub opacity: f32,
}

impl Toggles {
    /// The toggles as `look` sets them.
    pub fn of(look: &Look) -> Toggles {
        let (mode, shadows, ao, lit, opacity) =
            (look.mode, look.shadows, look.ao, look.lit, look.opacity);
        Toggles {
            mode,
            shadows,
            ao,
            lit,
            opacity,
        }
    }

    /// `look` with these toggles: what `render` draws with the same flags.
    pub fn apply(&self, look: &Look) -> Look {
        let mut l = look.clone();
        (l.mode, l.shadows, l.ao, l.lit, l.opacity) =
            (self.mode, self.shadows, self.ao, self.lit, self.opacity);
        l
    }

    /// What the mode can show of these toggles: shadows and AO only on balls and sticks
    /// (bs, vol+bs), lighting and opacity only of a volume (volume, vol+bs). The toggles keep
    /// the user's choices, so switching back to a mode restores them.
    pub fn effective(self) -> Toggles {
        let (model, volume) = match self.mode {
            Mode::Bs => (true, false),
            Mode::Volume => (false, true),
            Mode::VolBs => (true, true),
            Mode::Path => (false, false),
        };
        Toggles {
            shadows: self.shadows && model,
            ao: self.ao.filter(|_| model),
            lit: self.lit && volume,
            opacity: if volume { self.opacity } else { 1.0 },
            ..self
        }
    }

    /// The `bnsview render` flags of the effective toggles ([`Toggles::effective`]; those
    /// that differ from the defaults are all listed, so the line is complete).
    pub fn flags(&self) -> String {
        let t = self.effective();
        let mut s = format!("--mode {}", t.mode.name());
        if t.shadows {
            s += " --shadows";
        }
        if let Some(n) = t.ao {
            s += &format!(" --ao {n}");
        }
        if t.lit {
            s += " --lit";
        }
        if t.opacity != 1.0 {
            s += &format!(" --opacity {}", t.opacity);
        }
        s
    }
}

/// What a key asks for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    /// Show this mode.
    Mode(Mode),
    /// The next mode (bs → vol+bs → volume → path).
    NextMode,
    /// Shadows on/off.
    Shadows,
    /// Ambient occlusion on/off.
    Ao,
    /// Volume lighting on/off.
    Lit,
    /// Multiply the volume's opacity by this factor.
    Opacity(f32),
    /// Back to the first view.
    Reset,
    /// Print the current camera and mode as `bnsview render` flags.
    PrintCamera,
    /// Save the fully refined frame as a PNG.
    Screenshot,
    /// Play or pause the time steps.
    PlayPause,
    /// Go this many time steps forward (negative: back).
    Step(i32),
    /// Show or hide the list of keys.
    Help,
    /// Close the window.
    Quit,
}

/// Every key: its name (as `--script`'s `key NAME` spells it), the action, and what it does.
pub const KEYS: &[(&str, Action, &str)] = &[
    ("1", Action::Mode(Mode::Bs), "ball-and-stick"),
    ("2", Action::Mode(Mode::Volume), "volume"),
    ("3", Action::Mode(Mode::VolBs), "volume + ball-and-stick"),
    ("4", Action::Mode(Mode::Path), "path traced"),
    ("v", Action::NextMode, "next mode"),
    ("s", Action::Shadows, "shadows on/off"),
    ("a", Action::Ao, "ambient occlusion on/off"),
    ("l", Action::Lit, "volume lighting on/off"),
    ("]", Action::Opacity(1.25), "volume more opaque"),
    ("[", Action::Opacity(0.8), "volume more transparent"),
    ("r", Action::Reset, "reset the view"),
    ("c", Action::PrintCamera, "print the camera (render flags)"),
    ("p", Action::Screenshot, "screenshot (PNG)"),
    ("space", Action::PlayPause, "play / pause time steps"),
    ("right", Action::Step(1), "next time step"),
    ("left", Action::Step(-1), "previous time step"),
    ("h", Action::Help, "keys on/off"),
    ("?", Action::Help, "keys on/off"),
    ("q", Action::Quit, "quit"),
    ("escape", Action::Quit, "quit"),
];

/// The action of the key called `name` (see [`KEYS`]).
pub fn action(name: &str) -> Option<Action> {
    KEYS.iter().find(|(n, _, _)| *n == name).map(|(_, a, _)| *a)
}

/// The key names, for error messages.
pub fn key_names() -> String {
    KEYS.iter()
        .map(|(n, _, _)| *n)
        .collect::<Vec<_>>()
        .join(" ")
}

/// The lines of the help overlay (and of `h` printed to the terminal).
pub fn help_lines() -> Vec<String> {
    let mut v = vec!["left drag: orbit   right/middle drag: pan   wheel: zoom".to_string()];
    v.extend(
        KEYS.iter()
            .filter(|(n, _, _)| *n != "?")
            .map(|(n, _, what)| format!("{n:>6}  {what}")),
    );
    v
}

/// The toggles after `a` (`None`: the action changes no toggle). `ao_samples` is the AO ray
/// count switched on by the AO key.
pub fn toggle(t: Toggles, a: Action, ao_samples: u32) -> Option<Toggles> {
    Some(match a {
        Action::Mode(mode) => Toggles { mode, ..t },
        Action::NextMode => Toggles {
            mode: next_mode(t.mode),
            ..t
        },
        // Shadows and AO are alternatives, as on the command line.
        Action::Shadows => Toggles {
            shadows: !t.shadows,
            ao: None,
            ..t
        },
        Action::Ao => Toggles {
            ao: if t.ao.is_some() {
                None
            } else {
                Some(ao_samples)
            },
            shadows: false,
            ..t
        },
        Action::Lit => Toggles { lit: !t.lit, ..t },
        Action::Opacity(k) => Toggles {
            opacity: (t.opacity * k).clamp(1e-3, 1e3),
            ..t
        },
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_key_name_is_unique_and_found() {
        for (i, (n, a, _)) in KEYS.iter().enumerate() {
            assert_eq!(action(n), Some(*a));
            assert!(KEYS[..i].iter().all(|(m, _, _)| m != n), "{n} twice");
        }
        assert_eq!(action("x"), None);
    }

    #[test]
    fn v_visits_every_mode_and_returns() {
        let mut m = Mode::Bs;
        let mut seen = vec![m];
        for _ in 0..3 {
            m = next_mode(m);
            seen.push(m);
        }
        assert_eq!(next_mode(m), Mode::Bs);
        seen.sort_by_key(|m| m.name());
        seen.dedup();
        assert_eq!(seen.len(), 4);
    }

    #[test]
    fn shadows_and_ao_exclude_each_other_and_flags_list_them() {
        let t = Toggles {
            mode: Mode::VolBs,
            shadows: false,
            ao: None,
            lit: false,
            opacity: 1.0,
        };
        let s = toggle(t, Action::Shadows, 8).unwrap();
        assert!(s.shadows && s.ao.is_none());
        let a = toggle(s, Action::Ao, 8).unwrap();
        assert!(!a.shadows && a.ao == Some(8));
        assert_eq!(toggle(a, Action::Ao, 8).unwrap().ao, None);
        let o = toggle(toggle(a, Action::Opacity(2.0), 8).unwrap(), Action::Lit, 8).unwrap();
        assert_eq!(o.flags(), "--mode vol+bs --ao 8 --lit --opacity 2");
        assert_eq!(toggle(t, Action::Reset, 8), None);
        // Each mode shows what it can; switching back restores the rest.
        let v = toggle(o, Action::Mode(Mode::Volume), 8).unwrap();
        assert_eq!(v.flags(), "--mode volume --lit --opacity 2");
        let b = toggle(v, Action::Mode(Mode::Bs), 8).unwrap();
        assert_eq!(b.flags(), "--mode bs --ao 8");
        assert_eq!(
            toggle(b, Action::Mode(Mode::Path), 8).unwrap().flags(),
            "--mode path"
        );
        assert_eq!(toggle(b, Action::Mode(Mode::VolBs), 8).unwrap(), o);
    }
}
