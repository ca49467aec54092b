//! Rendering across MPI ranks (`mpirun -np 2 bnsview render ...`, the `mpi` feature, OpenMPI):
//! the image of two ranks is byte for byte the image of one process, for every kind of
//! integrator and for a giant frame streamed in bands; a rank's error ends the job with its
//! message. Without the feature, a launch as several processes is refused.

mod common;
use common::{bnsview, scratch};

#[cfg(not(feature = "mpi"))]
#[test]
fn a_build_without_mpi_launched_as_several_processes_refuses() {
    // The variables mpirun (OpenMPI) sets for rank 0 of 2.
    let mut c = bnsview();
    c.args(["render", "--scene", "nanobowl", "--size", "32x32", "-o"]);
    c.arg(scratch("nompi").join("a.png"));
    c.env("OMPI_COMM_WORLD_SIZE", "2")
        .env("OMPI_COMM_WORLD_RANK", "0");
    let err = common::refused(
        &mut c,
        &["2 processes", "built without MPI", "--features mpi"],
    );
    assert!(!err.contains("wrote"), "{err}");
}

#[cfg(feature = "mpi")]
mod with_mpi {
    use super::common::run;
    use super::*;
    use std::path::Path;
    use std::process::{Command, Stdio};
    use std::time::{Duration, Instant};

    /// `mpirun -np 2 bnsview ARGS` (as root in CI, more ranks than cores allowed), with a
    /// time limit so that a hang fails the test instead of the CI job: success, stderr.
    fn mpirun(args: &[&str], dir: &Path) -> (bool, String) {
        mpirun_np(2, args, dir)
    }

    /// [`mpirun`] with `np` ranks.
    fn mpirun_np(np: usize, args: &[&str], dir: &Path) -> (bool, String) {
        let mut c = Command::new("mpirun");
        c.args([
            "--allow-run-as-root",
            "--oversubscribe",
            "-np",
            &np.to_string(),
        ]);
        c.arg(env!("CARGO_BIN_EXE_bnsview"))
            .args(args)
            .current_dir(dir);
        within_limit(c)
    }

    /// Runs `c` to its end (stderr captured), failing the test after 300 s.
    fn within_limit(mut c: Command) -> (bool, String) {
        let args = format!("{c:?}");
        c.env_remove("BNS_ISA")
            .stdout(Stdio::null())
            .stderr(Stdio::piped());
        let mut child = c.spawn().expect("mpirun (apt install openmpi-bin)");
        let start = Instant::now();
        while child.try_wait().unwrap().is_none() {
            if start.elapsed() > Duration::from_secs(300) {
                child.kill().ok();
                panic!("{args} did not end in 300 s");
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        (out.status.success(), err)
    }

    /// Renders `args` with 2 ranks and with one process (one thread each) into `dir` and
    /// checks the files are identical; returns the ranks' stderr.
    fn same_as_one_process(args: &[&str], dir: &Path, name: &str) -> String {
        same_with_ranks(2, args, dir, name)
    }

    /// [`same_as_one_process`] with `np` ranks.
    fn same_with_ranks(np: usize, args: &[&str], dir: &Path, name: &str) -> String {
        let (two, one) = (format!("{name}-{np}.png"), format!("{name}-1.png"));
        let base = ["render", "--threads", "1", "-v"];
        let (ok, err) = mpirun_np(np, &[&base[..], args, &["-o", &two]].concat(), dir);
        assert!(ok, "{name}: {err}");
        let (ok, _, err1) = run(bnsview()
            .args(base)
            .args(args)
            .arg("-o")
            .arg(dir.join(&one)));
        assert!(ok, "{name}: {err1}");
        let (a, b) = (
            std::fs::read(dir.join(&two)).unwrap(),
            std::fs::read(dir.join(&one)).unwrap(),
        );
        assert!(
            a == b,
            "{name}: the image of {np} ranks differs from one process's"
        );
        err
    }

    #[test]
    fn two_ranks_render_the_image_of_one_process_in_every_mode() {
        let d = scratch("mpi-modes");
        let scene = [
            "--scene", "nanobowl", "--atoms", "3000", "--size", "203x150",
        ];
        for (name, flags) in [
            ("bs", &[][..]),
            (
                "volbs-lit",
                &["--mode", "vol+bs", "--lit", "--voxels-per-angstrom", "2"][..],
            ),
            ("ao", &["--ao", "4"][..]),
            ("path", &["--mode", "path", "--spp", "3"][..]),
        ] {
            let err = same_as_one_process(&[&scene[..], flags].concat(), &d, name);
            // -v: each rank's tiles (13 x 10 tiles: 5 rows of 13 each), reported once, by
            // rank 0.
            for r in ["rank 0/2: 65 tiles", "rank 1/2: 65 tiles"] {
                assert_eq!(err.matches(r).count(), 1, "{name}: {err}");
            }
            assert_eq!(err.matches("wrote ").count(), 1, "{name}: {err}");
        }
        // 3 ranks: rows of tiles 0, 3, 6, 9 | 1, 4, 7 | 2, 5, 8 (a rank with fewer rows, and
        // rank 0 receiving from two).
        let err = same_with_ranks(3, &scene, &d, "bs3");
        for r in [
            "rank 0/3: 52 tiles",
            "rank 1/3: 39 tiles",
            "rank 2/3: 39 tiles",
        ] {
            assert_eq!(err.matches(r).count(), 1, "3 ranks: {err}");
        }
        std::fs::remove_dir_all(d).ok();
    }

    #[test]
    fn two_ranks_stream_a_giant_frame_identical_to_one_process() {
        let d = scratch("mpi-giant");
        // 8208x8192 is over 256 MiB: streamed in bands of 2032 rows.
        let args = [
            "--scene",
            "nanobowl",
            "--atoms",
            "300",
            "--size",
            "8208x8192",
        ];
        let err = same_as_one_process(&args, &d, "giant");
        assert!(err.contains("stream:  2032 rows a band"), "{err}");
        let files: Vec<_> = std::fs::read_dir(&d)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(files.len(), 2, "only the two images: {files:?}");
        std::fs::remove_dir_all(d).ok();
    }

    #[test]
    fn a_ranks_error_ends_the_job_with_that_error() {
        // Rank 1's copy of the file is cut short (a node with a bad copy): every rank stops,
        // rank 0 reports rank 1's error with the file and line, and no image is written.
        let d = scratch("mpi-error");
        for r in ["0", "1"] {
            std::fs::create_dir_all(d.join(r)).unwrap();
        }
        let good = d.join("0/frame.xyz");
        let (ok, _, err) = run(bnsview()
            .args(["generate", "nanobowl", "--atoms", "300", "-o"])
            .arg(&good));
        assert!(ok, "{err}");
        let text = std::fs::read_to_string(&good).unwrap();
        let cut: String = text.lines().take(40).map(|l| format!("{l}\n")).collect();
        std::fs::write(d.join("1/frame.xyz"), cut).unwrap();
        let out = d.join("out.png");
        let script = format!(
            "cd {}/$OMPI_COMM_WORLD_RANK && exec {} render frame.xyz -o {}",
            d.display(),
            env!("CARGO_BIN_EXE_bnsview"),
            out.display()
        );
        let mut c = Command::new("mpirun");
        c.args([
            "--allow-run-as-root",
            "--oversubscribe",
            "-np",
            "2",
            "sh",
            "-c",
            &script,
        ]);
        let (ok, err) = within_limit(c);
        assert!(!ok, "{err}");
        assert!(err.contains("error: rank 1 of 2: frame.xyz:"), "{err}");
        assert_eq!(err.matches("error: ").count(), 1, "reported once: {err}");
        assert!(!out.exists());
        // A command that is not shared out is refused on every rank, reported once.
        let (ok, err) = mpirun(&["info", "--scene", "nanobowl"], &d);
        assert!(
            !ok && err.contains("only `bnsview render` is shared out"),
            "{err}"
        );
        std::fs::remove_dir_all(d).ok();
    }
}
