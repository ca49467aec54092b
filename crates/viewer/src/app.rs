//! The viewer's loop: inputs (window or script) → navigation and toggles → one refinement
//! step on the window thread → present; scenes of other time steps or settings come from the
//! background [`Loader`] and are swapped in only when ready.

use std::io::Write;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use render::{FrameInputs, Framebuffer, RenderSettings};
use scene::{Camera, Scene, SceneSettings, SharedModel, Sphere};
use spmd::Isa;

use crate::error::ViewError;
use crate::fit::{fit, fit_settings, fix_ranges, Fit, Ranges};
use crate::keys::{help_lines, toggle, Action, Toggles};
use crate::loader::{Answer, FrameSource, Loader, Request};
use crate::nav::Navigation;
use crate::overlay::{draw_lines, loading_lines, text_frame};
use crate::refine::Refiner;
use crate::script::Command;
use crate::window::{Input, Window};
use render::Mode;

/// The render and scene settings of a set of toggles (`Err`: why they cannot be shown).
pub type Configure = dyn Fn(&Toggles) -> Result<(SceneSettings, RenderSettings), String>;

/// How the viewer starts.
pub struct ViewConfig {
    /// Window size in pixels (the size of screenshots).
    pub size: (u32, u32),
    /// SIMD backend.
    pub isa: Isa,
    /// The toggles at start.
    pub toggles: Toggles,
    /// AO rays per hit when the AO key switches it on.
    pub ao_samples: u32,
    /// The settings of each set of toggles, exactly as `bnsview render` maps its flags.
    pub configure: Box<Configure>,
    /// The first camera, from the first scene's bounding sphere.
    pub camera: Box<dyn Fn(Sphere) -> Result<Camera, String>>,
    /// Time step shown first.
    pub first_frame: usize,
    /// Script lines to run instead of waiting for the user only (the window still works).
    pub script: Option<Vec<Command>>,
    /// Write one JSON line per presented frame and per key here.
    pub log: Option<PathBuf>,
    /// Screenshots may overwrite files.
    pub force: bool,
    /// Threads of the background builder's pool.
    pub build_threads: usize,
    /// Render previews at reduced resolution while the camera moves (off: every frame at
    /// full resolution, for benchmarks).
    pub preview: bool,
}

/// What a session did.
#[derive(Clone, Debug, Default)]
pub struct ViewReport {
    /// Frames presented.
    pub presented: u64,
    /// Screenshots written.
    pub screenshots: Vec<PathBuf>,
}

/// The scene on screen.
struct Shown {
    scene: Box<Scene>,
    frame: usize,
}

/// Everything the loop keeps.
struct App {
    cfg: ViewConfig,
    win: Window,
    loader: Loader,
    refiner: Refiner,
    nav: Navigation,
    home: Option<Navigation>,
    toggles: Toggles,
    settings: RenderSettings,
    /// Toggles waiting for a scene that can show them.
    pending: Option<Toggles>,
    shown: Option<Shown>,
    frames: Option<usize>,
    playing: bool,
    /// The newest request: (id, frame).
    waiting: Option<(u64, usize)>,
    /// The settings of the waiting request.
    asked: Option<SceneSettings>,
    /// The first time step's scene with the model and the volume, asked for once that step is
    /// on screen (so that mode keys need no build): its settings until asked for, then the
    /// request's id.
    upgrade: Upgrade,
    next_id: u64,
    /// Colour and density ranges of the first frame, fixed for the others.
    ranges: Option<Ranges>,
    help: bool,
    message: Option<(String, Instant)>,
    presented: u64,
    last_present: Instant,
    /// The input's name, for the screen shown while the first scene is made.
    name: String,
    /// When that screen was last drawn.
    loading_drawn: Option<Instant>,
    fps: f64,
    start: Instant,
    log: Option<std::io::BufWriter<std::fs::File>>,
    screenshots: Vec<PathBuf>,
    shot_count: u32,
}

/// The first time step's scene with the model and the volume (see `App::upgrade`).
#[derive(Clone, Debug, PartialEq)]
enum Upgrade {
    /// Not wanted (the first scene has both, or cannot), or already arrived.
    None,
    /// To ask for once the first scene is on screen.
    Wanted(Box<SceneSettings>),
    /// Asked for: the request's id, its time step and settings.
    Asked(u64, usize, Box<SceneSettings>),
}

impl Upgrade {
    /// Whether `id` is the upgrade's request.
    fn is(&self, id: u64) -> bool {
        matches!(self, Upgrade::Asked(a, ..) if *a == id)
    }
}

/// Opens the window over `source` and runs until the window closes, `q`, or the script's
/// `quit`.
pub fn run(cfg: ViewConfig, source: FrameSource) -> Result<ViewReport, ViewError> {
    let (w, h) = cfg.size;
    let name = source.name();
    let (scene_settings, settings) =
        (cfg.configure)(&cfg.toggles.effective()).map_err(ViewError::Settings)?;
    let win = Window::open(&format!("bnsview — {name}"), w, h)?;
    let log = match &cfg.log {
        Some(p) => Some(std::io::BufWriter::new(std::fs::File::create(p).map_err(
            |error| ViewError::Io {
                path: p.clone(),
                error,
            },
        )?)),
        None => None,
    };
    let loader = Loader::start(source, cfg.isa, cfg.build_threads);
    let mut app = App {
        win,
        loader,
        refiner: Refiner::new(w, h),
        nav: Navigation::from_camera(
            &Camera::look_at([0.0, 0.0, 1.0], [0.0; 3], [0.0, 1.0, 0.0], 45.0),
            Sphere {
                center: [0.0; 3],
                radius: 1.0,
            },
        ),
        home: None,
        toggles: cfg.toggles,
        settings,
        pending: None,
        shown: None,
        frames: None,
        playing: false,
        waiting: None,
        asked: None,
        upgrade: Upgrade::None,
        next_id: 0,
        ranges: None,
        help: false,
        message: None,
        presented: 0,
        last_present: Instant::now(),
        name: name.clone(),
        loading_drawn: None,
        fps: 0.0,
        start: Instant::now(),
        log,
        screenshots: Vec::new(),
        shot_count: 0,
        cfg,
    };
    app.refiner.set_kind(app.toggles.flags());
    // The first time step with what the mode needs, on screen as soon as it can be; then the
    // same step with the model and the volume behind it, so that switching modes needs no build.
    let first = app.cfg.first_frame;
    let superset = app.superset(&scene_settings);
    if superset != scene_settings {
        app.upgrade = Upgrade::Wanted(Box::new(superset));
    }
    app.request(first, scene_settings);
    let result = app.run_loop();
    if let Some(l) = app.log.as_mut() {
        let _ = l.flush();
    }
    result.map(|()| ViewReport {
        presented: app.presented,
        screenshots: app.screenshots,
    })
}

impl App {
    /// The scene settings of the toggles in vol+bs mode (model and volume), when valid.
    fn superset(&self, exact: &SceneSettings) -> SceneSettings {
        let both = Toggles {
            mode: Mode::VolBs,
            ..self.toggles
        };
        match (self.cfg.configure)(&both.effective()) {
            Ok((s, _)) if s.model.is_some() && s.volume.is_some() => s,
            _ => exact.clone(),
        }
    }

    fn request(&mut self, frame: usize, settings: SceneSettings) {
        // The same scene is already on its way: asking again would only restart its build
        // (a newer request stops the one being built).
        if self.waiting.is_some_and(|w| w.1 == frame) && self.asked.as_ref() == Some(&settings) {
            return;
        }
        self.asked = Some(settings.clone());
        self.next_id += 1;
        self.waiting = Some((self.next_id, frame));
        self.loader.request(Request {
            id: self.next_id,
            frame,
            settings,
            shared: None,
        });
    }

    /// The scene settings of `t` with the first frame's ranges fixed.
    fn needs(&self, t: &Toggles) -> Result<(SceneSettings, RenderSettings), String> {
        let (mut s, r) = (self.cfg.configure)(&t.effective())?;
        if let Some(ranges) = self.ranges {
            fix_ranges(&mut s, ranges);
        }
        Ok((s, r))
    }

    fn say(&mut self, msg: String) {
        eprintln!("{msg}");
        self.message = Some((msg, Instant::now()));
    }

    fn log(&mut self, line: String) {
        if let Some(l) = self.log.as_mut() {
            let t = self.start.elapsed().as_secs_f64();
            let _ = writeln!(l, "{{\"t\":{t:.6},{line}}}");
        }
    }

    fn run_loop(&mut self) -> Result<(), ViewError> {
        let mut script = self.cfg.script.take().unwrap_or_default().into_iter();
        let mut wait: Option<Command> = None;
        let mut wait_target = 0u64;
        loop {
            if !self.win.is_open() {
                return Ok(());
            }
            let mut moved = false;
            for i in self.win.inputs() {
                if self.apply(i, &mut moved)? {
                    return Ok(());
                }
            }
            self.receive()?;
            // Script: run lines, each applied at once, until one has to wait.
            loop {
                if let Some(w) = &wait {
                    let ready = match w {
                        // Done also when nothing more will be presented.
                        Command::WaitFrames(_) => {
                            self.presented >= wait_target || (!moved && self.still())
                        }
                        _ => !moved && self.still(),
                    };
                    if !ready {
                        break;
                    }
                    if let Some(Command::Screenshot(p)) = wait.take() {
                        self.screenshot(Some(p))?;
                    }
                }
                let Some(c) = script.next() else { break };
                let input = match c {
                    Command::Orbit(a, e) => Input::Orbit(a, e),
                    Command::Pan(x, y) => Input::Pan(x, y),
                    Command::Zoom(f) => Input::Zoom(f),
                    Command::Quit => Input::Key(Action::Quit),
                    Command::Key(a) => Input::Key(a),
                    Command::Frame(k) => {
                        self.playing = false;
                        self.go_to(k);
                        continue;
                    }
                    Command::WaitFrames(n) => {
                        wait_target = self.presented + n as u64;
                        wait = Some(c);
                        continue;
                    }
                    Command::WaitStill | Command::Screenshot(_) => {
                        wait = Some(c);
                        continue;
                    }
                };
                if self.apply(input, &mut moved)? {
                    return Ok(());
                }
            }
            self.advance_playback();
            if !self.draw(moved && self.cfg.preview)? {
                // Nothing to draw: keep the window responsive without spinning.
                self.win.pump();
                std::thread::sleep(Duration::from_millis(2));
            }
        }
    }

    /// Applies one input; `true` to quit. Camera moves set `moved`.
    fn apply(&mut self, i: Input, moved: &mut bool) -> Result<bool, ViewError> {
        match i {
            Input::Orbit(a, e) => self.nav = self.nav.orbit(a, e),
            Input::Pan(x, y) => self.nav = self.nav.pan(x, y, self.cfg.size.1),
            Input::Zoom(f) => self.nav = self.nav.zoom(f),
            Input::Key(Action::Quit) => return Ok(true),
            Input::Key(a) => self.key(a)?,
        }
        // A camera move, or a new mode or lighting: first a quick preview, then refine.
        let quick = match i {
            Input::Key(a) => toggle(self.toggles, a, 1).is_some(),
            _ => true,
        };
        if quick {
            *moved = true;
            self.refiner.invalidate();
        }
        Ok(false)
    }

    /// Fully refined, nothing loading or pending.
    fn still(&self) -> bool {
        self.shown.is_some() && self.refiner.done && !self.loader.busy() && self.pending.is_none()
    }

    fn key(&mut self, a: Action) -> Result<(), ViewError> {
        self.log(format!("\"key\":\"{a:?}\""));
        match a {
            Action::Reset => {
                if let Some(h) = self.home {
                    self.nav = h;
                    self.refiner.invalidate();
                }
            }
            Action::PrintCamera => {
                println!("--camera '{}' {}", self.nav.spec(), self.toggles.flags())
            }
            Action::Screenshot => self.screenshot(None)?,
            Action::PlayPause if self.frames == Some(1) => {
                self.say("one time step: nothing to play".into());
            }
            Action::PlayPause => {
                self.playing = !self.playing;
                let at_end = match (&self.shown, self.frames) {
                    (Some(s), Some(n)) => s.frame + 1 >= n,
                    _ => false,
                };
                if self.playing && at_end {
                    self.go_to(0);
                }
            }
            Action::Step(d) => {
                self.playing = false;
                if let Some(s) = &self.shown {
                    // From the step on its way, if any: two quick presses go two steps.
                    let from = self.waiting.map_or(s.frame, |w| w.1);
                    let k = from as i64 + d as i64;
                    let last = self.frames.map_or(i64::MAX, |n| n as i64 - 1);
                    self.go_to(k.clamp(0, last.max(0)) as usize);
                }
            }
            Action::Help => {
                self.help = !self.help;
                if self.help {
                    help_lines().iter().for_each(|l| eprintln!("{l}"));
                }
                self.refiner.invalidate();
            }
            _ => {
                let base = self.pending.unwrap_or(self.toggles);
                if let Some(t) = toggle(base, a, self.cfg.ao_samples) {
                    self.set_toggles(t);
                }
            }
        }
        Ok(())
    }

    /// Shows `t` now if the scene on screen can, else asks the loader for one that can.
    fn set_toggles(&mut self, t: Toggles) {
        let (need, rs) = match self.needs(&t) {
            Ok(v) => v,
            Err(e) => {
                self.say(format!("{}: {e}", t.flags()));
                return;
            }
        };
        let Some(shown) = self.shown.as_mut() else {
            self.toggles = t;
            self.settings = rs;
            return;
        };
        match fit(&shown.scene, &need) {
            Fit::Serves => {}
            Fit::NewTf(tf) if shown.scene.set_transfer_function(&tf) => {}
            _ => {
                let frame = shown.frame;
                self.pending = Some(t);
                // The upgrade on its way serves these toggles: swapping it in applies them.
                if let Upgrade::Asked(_, f, sup) = &self.upgrade {
                    let serves = !matches!(fit_settings(sup, &need), Fit::Rebuild);
                    if serves && *f == frame && self.waiting.is_none() {
                        self.say(format!("building the volume for {}…", t.flags()));
                        return;
                    }
                }
                self.say(format!("building the scene for {}…", t.flags()));
                self.request(frame, need);
                return;
            }
        }
        self.refiner.set_kind(t.flags());
        self.toggles = t;
        self.settings = rs;
        self.refiner.invalidate();
    }

    /// The upgrade will not be swapped in: toggles that waited for it ask for their own scene.
    fn upgrade_lost(&mut self) {
        let (Some(t), None, Some(shown)) = (self.pending, self.waiting, &self.shown) else {
            return;
        };
        let frame = shown.frame;
        match self.needs(&t) {
            Ok((need, _)) => self.request(frame, need),
            Err(e) => self.say(e),
        }
    }

    fn go_to(&mut self, k: usize) {
        if let Some(n) = self.frames {
            if k >= n {
                self.say(format!("no time step {k}: the input has {n}"));
                return;
            }
        }
        // Back to the step on screen (`←` on the first, `→` then `←`): a step on its way is
        // no longer wanted, and the scene on screen serves the toggles if it can (it may hold
        // the volume too: rebuilding it would lose that).
        if self.shown.as_ref().is_some_and(|s| s.frame == k) {
            if self.waiting.is_some_and(|w| w.1 != k) {
                self.waiting = None;
                self.next_id += 1;
                self.loader.withdraw(self.next_id);
            }
            let t = self.pending.take().unwrap_or(self.toggles);
            self.set_toggles(t);
            return;
        }
        let t = self.pending.unwrap_or(self.toggles);
        match self.needs(&t) {
            Ok((s, _)) => self.request(k, s),
            Err(e) => self.say(e),
        }
    }

    /// Plays on: when the frame on screen has been presented and the next is not yet asked
    /// for, ask for it (it is built while this one is on screen).
    fn advance_playback(&mut self) {
        if !self.playing || self.waiting.is_some() || self.presented == 0 {
            return;
        }
        let (Some(s), Some(n)) = (&self.shown, self.frames) else {
            return;
        };
        if s.frame + 1 >= n {
            self.playing = false;
            return;
        }
        let k = s.frame + 1;
        self.go_to(k);
    }

    /// Takes the loader's answers (never waits for one).
    fn receive(&mut self) -> Result<(), ViewError> {
        while let Some(a) = self.loader.poll() {
            match a {
                Answer::Frames(Ok(n)) => self.frames = Some(n),
                Answer::Frames(Err(e)) => self.say(format!("counting time steps: {e}")),
                Answer::Skipped { id } => {
                    // A newer request came first (a mode key, another step): it builds what is
                    // needed, and a mode key later builds the volume if it is missing.
                    if self.upgrade.is(id) {
                        self.upgrade = Upgrade::None;
                    }
                }
                Answer::Cancelled { id, frame, spent_s } => {
                    // As skipped, but stopped part way: logged, so the time it cost shows.
                    if self.upgrade.is(id) {
                        self.upgrade = Upgrade::None;
                    }
                    self.log(format!("\"cancelled\":{frame},\"spent_s\":{spent_s:.6}"));
                }
                Answer::Built {
                    id,
                    frame,
                    scene,
                    read_s,
                    build_s,
                } => {
                    if self.upgrade.is(id) {
                        self.upgrade = Upgrade::None;
                        // Swapped in only over the step it was made for, and only when no
                        // other step is on its way. A request for this step (a key pressed
                        // before the upgrade came) is dropped: swapping in applies the key,
                        // and asks again only if the upgrade does not serve it.
                        let here = self.shown.as_ref().is_some_and(|s| s.frame == frame);
                        let this_step = self.waiting.is_none_or(|w| w.1 == frame);
                        match scene {
                            Ok(s) if here && this_step => {
                                self.waiting = None;
                                self.swap_in(s, frame, read_s, build_s, true)?
                            }
                            Ok(_) => {
                                self.log(format!("\"discarded\":{frame},\"build_s\":{build_s:.6}"));
                                self.upgrade_lost();
                            }
                            Err(e) => {
                                self.say(format!("{e}: the volume is built when a key needs it"));
                                self.upgrade_lost();
                            }
                        }
                        continue;
                    }
                    if self.waiting.is_none_or(|w| w.0 != id) {
                        // Superseded while it was built: logged, so waste shows.
                        self.log(format!("\"discarded\":{frame},\"build_s\":{build_s:.6}"));
                        continue;
                    }
                    self.waiting = None;
                    match scene {
                        Ok(s) => self.swap_in(s, frame, read_s, build_s, false)?,
                        Err(e) if self.shown.is_none() => return Err(ViewError::Scene(e)),
                        Err(e) => {
                            self.playing = false;
                            self.pending = None;
                            self.say(format!("time step {frame}: {e}"));
                        }
                    }
                }
            }
        }
        Ok(())
    }

    fn swap_in(
        &mut self,
        mut s: Box<Scene>,
        frame: usize,
        read_s: f64,
        build_s: f64,
        upgrade: bool,
    ) -> Result<(), ViewError> {
        // The ranges of the first step shown (the density range: of the first one shown with
        // a volume), fixed for the others.
        let color = s.model.as_ref().and_then(|m| m.color_range);
        let density = s.volume.as_ref().map(|d| d.tf_max);
        let r = self.ranges.get_or_insert((color, density));
        r.1 = r.1.or(density);
        if let Some(r) = self.ranges {
            fix_ranges(&mut s.settings, r);
        }
        if self.home.is_none() {
            let cam = (self.cfg.camera)(s.sphere).map_err(ViewError::Settings)?;
            self.nav = Navigation::from_camera(&cam, s.sphere);
            self.home = Some(self.nav);
        }
        self.log(format!(
            "\"loaded\":{frame},\"read_s\":{read_s:.6},\"build_s\":{build_s:.6},\"upgrade\":{upgrade}"
        ));
        if let Some(old) = self.shown.replace(Shown { scene: s, frame }) {
            // Freeing a large scene takes milliseconds: not on the window's thread.
            let _ = std::thread::Builder::new().spawn(move || drop(old));
        }
        if let Upgrade::Wanted(mut sup) = std::mem::replace(&mut self.upgrade, Upgrade::None) {
            if let Some(r) = self.ranges {
                fix_ranges(&mut sup, r);
            }
            self.next_id += 1;
            // The model on screen is this step's: shared, not built (and held) twice.
            let shared = self.shown.as_ref().and_then(|sh| {
                let (model, settings) = (sh.scene.model.clone()?, sh.scene.settings.clone());
                Some(SharedModel { model, settings })
            });
            self.loader.request(Request {
                id: self.next_id,
                frame,
                settings: (*sup).clone(),
                shared,
            });
            self.upgrade = Upgrade::Asked(self.next_id, frame, sup);
        }
        if let Some(t) = self.pending.take() {
            self.set_toggles(t);
        } else {
            // The opacity may have changed since the request.
            self.set_toggles(self.toggles);
        }
        self.refiner.invalidate();
        Ok(())
    }

    /// One refinement step and present; `false` when there was nothing to draw.
    fn draw(&mut self, moved: bool) -> Result<bool, ViewError> {
        let Some(shown) = &self.shown else {
            self.draw_loading()?;
            return Ok(false);
        };
        if self.refiner.done && !moved {
            // Nothing to refine. Checked before the frame's inputs are made: a volume's
            // inputs check its empty-space map's fingerprint (~5 ms for ns740k at 4 voxels/Å),
            // which every idle turn of the loop paid, taking the core a build was using.
            return Ok(false);
        }
        let (camera, m, isa) = (self.nav.camera(), self.toggles.mode, self.cfg.isa);
        let step = with_inputs(shown, m, &self.settings, &camera, |inp| {
            self.refiner.step(inp, &self.settings, isa, moved)
        })?;
        let Some(step) = step else {
            return Ok(false);
        };
        let frame = shown.frame;
        let now = Instant::now();
        let dt = now.duration_since(self.last_present).as_secs_f64();
        self.last_present = now;
        self.fps = if self.presented == 0 {
            0.0
        } else {
            1.0 / dt.max(1e-6)
        };
        if self.help || self.message.is_some() {
            let mut fb = Framebuffer {
                width: self.cfg.size.0,
                height: self.cfg.size.1,
                pixels: self.refiner.shown.clone(),
            };
            self.overlay(&mut fb);
            self.win.present(&fb.pixels)?;
        } else {
            self.win.present(&self.refiner.shown)?;
        }
        self.presented += 1;
        let title = self.title(frame, step.scale, step.samples);
        self.win.set_title(&title);
        let loading = self.loader.busy();
        self.log(format!(
            "\"presented\":{},\"frame\":{frame},\"mode\":\"{}\",\"scale\":{},\"samples\":{},\"render_s\":{:.6},\"loading\":{loading}",
            self.presented, m.name(), step.scale, step.samples, step.render_s
        ));
        Ok(true)
    }

    /// While the first scene is made: a black frame that says so, redrawn every quarter
    /// second with the time taken (and the title), so the window is not blank meanwhile.
    fn draw_loading(&mut self) -> Result<(), ViewError> {
        if self
            .loading_drawn
            .is_some_and(|t| t.elapsed() < Duration::from_millis(250))
        {
            return Ok(());
        }
        self.loading_drawn = Some(Instant::now());
        let frame = self.waiting.map_or(self.cfg.first_frame, |w| w.1);
        let secs = self.start.elapsed().as_secs_f64();
        let mut lines = loading_lines(&self.name, frame, secs);
        lines.extend(self.message.iter().map(|(m, _)| m.clone()));
        let (w, h) = self.cfg.size;
        self.win.present(&text_frame(w, h, &lines).pixels)?;
        self.win
            .set_title(&format!("bnsview — {} — loading", self.name));
        Ok(())
    }

    fn title(&self, frame: usize, scale: u32, samples: u32) -> String {
        let n = self.frames.map_or("?".into(), |n| n.to_string());
        let quality = if scale > 1 {
            format!("preview 1/{scale}")
        } else if self.settings.is_linear() {
            format!("{samples}/{} spp", self.settings.spp)
        } else {
            "full".into()
        };
        let state = match (self.playing, self.waiting) {
            (true, _) => " — playing",
            (false, Some(_)) => " — loading",
            _ => "",
        };
        format!(
            "bnsview — frame {}/{n} — {}{} — {:.1} fps — {} — {quality}{state} — h: keys",
            frame + 1,
            self.toggles.mode.name(),
            self.settings.describe(),
            self.fps,
            self.cfg.isa,
        )
    }

    /// The help and the last message, drawn over the picture (never into screenshots).
    fn overlay(&mut self, fb: &mut Framebuffer) {
        let mut lines = Vec::new();
        if self.help {
            lines = help_lines();
        }
        if let Some((m, t)) = &self.message {
            if t.elapsed() < Duration::from_secs(4) {
                lines.push(m.clone());
            } else {
                self.message = None;
            }
        }
        draw_lines(fb, &lines);
    }

    /// Writes the fully refined frame (what `bnsview render` makes of this view) to `path`,
    /// or to the next free `bnsview_view_NNN.png`.
    fn screenshot(&mut self, path: Option<PathBuf>) -> Result<(), ViewError> {
        let Some(shown) = &self.shown else {
            return Err(ViewError::ScriptStep(
                "screenshot before the first frame".into(),
            ));
        };
        let (camera, m, isa) = (self.nav.camera(), self.toggles.mode, self.cfg.isa);
        let fb = with_inputs(shown, m, &self.settings, &camera, |inp| {
            self.refiner.screenshot(inp, &self.settings, isa)
        })?;
        let scripted = path.is_some();
        let path = match path {
            Some(p) => p,
            None => loop {
                self.shot_count += 1;
                let p = PathBuf::from(format!("bnsview_view_{:03}.png", self.shot_count));
                if !p.exists() {
                    break p;
                }
            },
        };
        if path.exists() && !self.cfg.force {
            let e = ViewError::Exists { path };
            if scripted {
                return Err(e);
            }
            self.say(e.to_string());
            return Ok(());
        }
        fb.save(&path)?;
        let msg = format!(
            "wrote {} (bnsview render --camera '{}' {} --size {}x{})",
            path.display(),
            self.nav.spec(),
            self.toggles.flags(),
            self.cfg.size.0,
            self.cfg.size.1
        );
        self.say(msg);
        self.screenshots.push(path);
        Ok(())
    }
}

/// Calls `f` with what mode `m` draws of the scene on screen (as `render` builds it for that
/// mode: no volume for bs and path, no model for volume).
fn with_inputs<R>(
    shown: &Shown,
    m: Mode,
    settings: &RenderSettings,
    camera: &Camera,
    f: impl FnOnce(&FrameInputs) -> R,
) -> R {
    let volume = if matches!(m, Mode::Volume | Mode::VolBs) {
        shown.scene.volume_scene(settings.march)
    } else {
        None
    };
    f(&FrameInputs {
        model: shown.scene.model.as_deref().filter(|_| m != Mode::Volume),
        volume: volume.as_ref(),
        camera,
    })
}
