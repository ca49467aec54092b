//! The background loader: reads and builds the scene of a time step on its own thread and
//! its own thread pool, at the lowest scheduling priority, so the window thread never waits
//! for a build and its frames keep their speed; the window polls for the result and swaps it
//! in when it is ready.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{channel, Receiver, Sender, TryRecvError};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Instant;

use molecule::read::{CancelTest, FrameIndex, ReadError, Trajectory};
use molecule::Molecule;
use scene::{Progress, Scene, SceneError, SceneSettings, SharedModel};
use spmd::Isa;

/// Where the time steps come from.
pub enum FrameSource {
    /// A trajectory file (random access after its frames are counted).
    File(Box<Trajectory>),
    /// One frame already in memory (a built-in scene or a single-frame file), with its name.
    One(Box<Molecule>, String),
}

impl FrameSource {
    /// The time steps of `input` and the index of its frame `frame` (negative: from the end):
    /// a file is opened (its frames read as they are shown), a built-in scene generated.
    pub fn open(input: &scene::Input, frame: i64) -> Result<(FrameSource, usize), SceneError> {
        match input {
            scene::Input::File { path, options } => {
                let mut t = molecule::read::open(path, options)?;
                let first = t.resolve_frame(FrameIndex::from(frame))?;
                Ok((FrameSource::File(Box::new(t)), first))
            }
            scene::Input::Builtin { .. } => {
                let l = input.load(frame, false, &scene::Progress::none())?;
                Ok((FrameSource::One(Box::new(l.molecule), l.source), 0))
            }
        }
    }

    /// Human name of the source.
    pub fn name(&self) -> String {
        match self {
            FrameSource::File(t) => t.path().display().to_string(),
            FrameSource::One(_, n) => n.clone(),
        }
    }

    fn count(&mut self) -> Result<usize, String> {
        match self {
            FrameSource::File(t) => t.count_frames().map_err(|e| e.to_string()),
            FrameSource::One(..) => Ok(1),
        }
    }

    /// Time step `k`; a file's read stops once `cancel` returns true (`Ok(None)`).
    fn read(&mut self, k: usize, cancel: CancelTest) -> Result<Option<Molecule>, String> {
        match self {
            FrameSource::File(t) => match t.read_frame_unless(k, cancel) {
                Ok(m) => Ok(Some(m)),
                Err(ReadError::Cancelled { .. }) => Ok(None),
                Err(e) => Err(e.to_string()),
            },
            FrameSource::One(m, _) if k == 0 => Ok(Some((**m).clone())),
            FrameSource::One(_, n) => Err(format!("{n}: has one frame, no frame {k}")),
        }
    }
}

/// A scene to build.
#[derive(Clone)]
pub struct Request {
    /// Which request this is (answers carry it back).
    pub id: u64,
    /// Time step (0-based).
    pub frame: usize,
    /// What the scene holds.
    pub settings: SceneSettings,
    /// A model already built for this time step that the scene may share instead of
    /// building its own ([`Scene::build_sharing`]).
    pub shared: Option<SharedModel>,
}

/// What the loader sends back.
pub enum Answer {
    /// The scene of a request (or why it could not be made).
    Built {
        /// The request's id.
        id: u64,
        /// Its time step.
        frame: usize,
        /// The scene.
        scene: Result<Box<Scene>, String>,
        /// Seconds reading the frame.
        read_s: f64,
        /// Seconds building the scene.
        build_s: f64,
    },
    /// A request dropped for a newer one before it was started.
    Skipped {
        /// The request's id.
        id: u64,
    },
    /// A request whose build was stopped part way because a newer one came.
    Cancelled {
        /// The request's id.
        id: u64,
        /// Its time step.
        frame: usize,
        /// Seconds spent reading and building before it stopped.
        spent_s: f64,
    },
    /// How many time steps the source has (counted after the first scene is built).
    Frames(Result<usize, String>),
}

/// The loader thread and its channels.
pub struct Loader {
    tx: Option<Sender<Request>>,
    /// Id of the newest request sent: a build of any other is no longer wanted.
    newest: Arc<AtomicU64>,
    rx: Receiver<Answer>,
    pending: usize,
    handle: Option<JoinHandle<()>>,
}

impl Loader {
    /// Starts the loader over `source` with a pool of `threads` build threads.
    pub fn start(source: FrameSource, isa: Isa, threads: usize) -> Loader {
        let (tx, requests) = channel::<Request>();
        let (answers, rx) = channel();
        let newest = Arc::new(AtomicU64::new(0));
        let wanted = newest.clone();
        let handle = std::thread::Builder::new()
            .name("bnsview-loader".into())
            .spawn(move || serve(source, isa, threads, requests, answers, wanted))
            .ok();
        Loader {
            tx: Some(tx),
            newest,
            rx,
            pending: 0,
            handle,
        }
    }

    /// Asks for a scene; requests made before it that are not started yet are dropped, and
    /// one being built stops at its next check (ids must grow from one request to the next).
    pub fn request(&mut self, r: Request) {
        // Before the send, so the loader never builds this request while it looks stale.
        self.newest.store(r.id, Ordering::Relaxed);
        if let Some(tx) = &self.tx {
            if tx.send(r).is_ok() {
                self.pending += 1;
            }
        }
    }

    /// No request made so far is wanted any more: one being built stops at its next check
    /// and is answered as cancelled. `id` is greater than every request's so far and below
    /// every later one's.
    pub fn withdraw(&mut self, id: u64) {
        self.newest.store(id, Ordering::Relaxed);
    }

    /// An answer, if one is ready (never waits).
    pub fn poll(&mut self) -> Option<Answer> {
        match self.rx.try_recv() {
            Ok(a) => {
                if let Answer::Built { .. } | Answer::Skipped { .. } | Answer::Cancelled { .. } = a
                {
                    self.pending = self.pending.saturating_sub(1);
                }
                Some(a)
            }
            Err(TryRecvError::Empty) => None,
            Err(TryRecvError::Disconnected) => {
                self.pending = 0;
                None
            }
        }
    }

    /// Whether a requested scene has not arrived yet.
    pub fn busy(&self) -> bool {
        self.pending > 0
    }
}

impl Drop for Loader {
    fn drop(&mut self) {
        self.tx = None;
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

/// Puts the calling thread at the lowest scheduling priority, so that while the window renders,
/// builds take only the CPU time the frames leave: Linux's idle policy (`SCHED_IDLE`: a frame's
/// thread that wakes takes the core back at once, not at the end of the build thread's time
/// slice), and nice 19 where that policy is refused.
fn yield_to_the_window() {
    #[cfg(target_os = "linux")]
    // SAFETY: setpriority only reads its three integer arguments and sched_setscheduler reads
    // the `sched_param` that lives on this stack frame for the whole call; on Linux `who`/`pid`
    // = 0 names the calling thread, so only this thread's priority changes. A failure (e.g.
    // forbidden by a policy) leaves the priority as it was, which is harmless.
    unsafe {
        libc::setpriority(libc::PRIO_PROCESS, 0, 19);
        let idle = libc::sched_param { sched_priority: 0 };
        libc::sched_setscheduler(0, libc::SCHED_IDLE, &idle);
    }
}

/// The loader thread: the newest request first (older waiting ones are answered as
/// skipped), read and build on the loader's own pool (both stopped as soon as a newer
/// request is made — the read within a megabyte of input, the build within a slab pass, a
/// chunk of the bond search or a piece of the BVH — and answered as cancelled), send.
fn serve(
    mut source: FrameSource,
    isa: Isa,
    threads: usize,
    requests: Receiver<Request>,
    answers: Sender<Answer>,
    newest: Arc<AtomicU64>,
) {
    yield_to_the_window();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.max(1))
        .thread_name(|i| format!("bnsview-build-{i}"))
        .start_handler(|_| yield_to_the_window())
        .build();
    let mut counted = false;
    while let Ok(mut r) = requests.recv() {
        // Only the newest waiting request matters; the others are answered as skipped.
        while let Ok(newer) = requests.try_recv() {
            if answers.send(Answer::Skipped { id: r.id }).is_err() {
                return;
            }
            r = newer;
        }
        let t0 = Instant::now();
        let (wanted, id) = (newest.clone(), r.id);
        let m = source.read(
            r.frame,
            Arc::new(move || wanted.load(Ordering::Relaxed) != id),
        );
        let read_s = t0.elapsed().as_secs_f64();
        let t = Instant::now();
        let stale = || newest.load(Ordering::Relaxed) != r.id;
        let cancelled = || Answer::Cancelled {
            id: r.id,
            frame: r.frame,
            spent_s: t0.elapsed().as_secs_f64(),
        };
        let done = |scene: Result<Scene, String>| Answer::Built {
            id: r.id,
            frame: r.frame,
            scene: scene.map(Box::new),
            read_s,
            build_s: t.elapsed().as_secs_f64(),
        };
        let answer = match m {
            Ok(None) => cancelled(),
            Ok(Some(m)) => {
                let build = || {
                    let progress = Progress {
                        cancelled: &stale,
                        ..Progress::none()
                    };
                    Scene::build_sharing(isa, &m, &r.settings, &progress, r.shared.as_ref())
                };
                match pool.as_ref().map_or_else(|_| build(), |p| p.install(build)) {
                    Err(SceneError::Cancelled) => cancelled(),
                    scene => done(scene.map_err(|e| e.to_string())),
                }
            }
            Err(e) => done(Err(e)),
        };
        if answers.send(answer).is_err() {
            return;
        }
        if !counted {
            counted = true;
            if answers.send(Answer::Frames(source.count())).is_err() {
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use std::time::{Duration, Instant};

    use molecule::scenes::{generate, SceneName};
    use scene::{ModelSettings, SceneSettings, VolumeSettings};
    use spmd::Isa;

    use super::*;

    #[test]
    fn a_cancelled_read_is_no_error_and_the_step_is_read_again_in_full() {
        let dir = std::env::temp_dir().join(format!("bns_loader_read_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("two.xyz");
        let mut text = Vec::new();
        for k in 0..2 {
            let mut m = generate(SceneName::Nanobowl, Some(2000), 1);
            m.x.iter_mut().for_each(|x| *x += k as f32);
            molecule::write::write_xyz(&mut text, &m, "").unwrap();
        }
        std::fs::write(&path, &text).unwrap();
        let input = scene::Input::File {
            path: path.clone(),
            options: Default::default(),
        };
        let (mut source, first) = FrameSource::open(&input, 0).unwrap();
        assert_eq!(first, 0);
        // Stopped: no molecule and no error (the loader answers "cancelled").
        assert!(matches!(source.read(1, Arc::new(|| true)), Ok(None)));
        let m = source.read(1, Arc::new(|| false)).unwrap().unwrap();
        let want = molecule::read::read_first(&path, &Default::default()).unwrap();
        assert_eq!(m.len(), want.len());
        assert!(
            m.x.iter().zip(&want.x).all(|(a, b)| a - b == 1.0),
            "frame 1"
        );
        let again = source.read(1, Arc::new(|| false)).unwrap().unwrap();
        assert!((m.x, m.y, m.z) == (again.x, again.y, again.z));
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_newer_request_stops_the_build_in_progress() {
        // A density volume of 90K atoms on the scalar backend: seconds of work, so the
        // second request comes while the first is read or built.
        let m = generate(SceneName::Ns90k, None, 1);
        let source = FrameSource::One(Box::new(m), "ns90k".into());
        let mut l = Loader::start(source, Isa::Scalar, 2);
        let full = SceneSettings {
            model: Some(ModelSettings::default()),
            volume: Some(VolumeSettings::default()),
            budget_bytes: Some(u64::MAX),
            ..SceneSettings::default()
        };
        let model = SceneSettings {
            volume: None,
            ..full.clone()
        };
        l.request(Request {
            id: 1,
            frame: 0,
            settings: full,
            shared: None,
        });
        std::thread::sleep(Duration::from_millis(50));
        l.request(Request {
            id: 2,
            frame: 0,
            settings: model,
            shared: None,
        });
        let start = Instant::now();
        let mut first = Vec::new();
        let second = loop {
            assert!(start.elapsed() < Duration::from_secs(300), "no answer");
            match l.poll() {
                Some(Answer::Built { id: 2, scene, .. }) => break scene.unwrap(),
                Some(Answer::Built { id, .. }) => panic!("request {id} was built to the end"),
                Some(Answer::Skipped { id }) | Some(Answer::Cancelled { id, .. }) => first.push(id),
                Some(Answer::Frames(_)) => {}
                None => std::thread::sleep(Duration::from_millis(5)),
            }
        };
        assert_eq!(first, [1]);
        assert!(second.volume.is_none() && second.model.is_some());
        assert!(!l.busy());
    }

    /// The first time step's upgrade shares the model on screen: the scene sent back holds the
    /// same model (no second BVH), and its volume.
    #[test]
    fn a_request_with_the_model_on_screen_shares_it() {
        let m = generate(SceneName::Nanobowl, Some(3000), 1);
        let source = FrameSource::One(Box::new(m), "nanobowl".into());
        let mut l = Loader::start(source, Isa::Scalar, 2);
        let model = SceneSettings {
            model: Some(ModelSettings::default()),
            budget_bytes: Some(u64::MAX),
            ..SceneSettings::default()
        };
        let full = SceneSettings {
            volume: Some(VolumeSettings::default()),
            ..model.clone()
        };
        let wait = |l: &mut Loader, want: u64| loop {
            match l.poll() {
                Some(Answer::Built { id, scene, .. }) if id == want => break scene.unwrap(),
                Some(Answer::Built { id, .. }) => panic!("request {id} answered"),
                _ => std::thread::sleep(Duration::from_millis(5)),
            }
        };
        l.request(Request {
            id: 1,
            frame: 0,
            settings: model,
            shared: None,
        });
        let first = wait(&mut l, 1);
        let shared = SharedModel {
            model: first.model.clone().unwrap(),
            settings: first.settings.clone(),
        };
        l.request(Request {
            id: 2,
            frame: 0,
            settings: full,
            shared: Some(shared.clone()),
        });
        let up = wait(&mut l, 2);
        assert!(Arc::ptr_eq(up.model.as_ref().unwrap(), &shared.model));
        assert!(up.volume.is_some());
    }
}
