//! A [`PngStream`] encoded on a thread of its own, so that rendering band k+1 overlaps encoding
//! band k: the encoder is one thread and costs 2-4 s per 512 megapixels (BENCHMARKS.md, "Giant
//! frames and MPI"). Two bands are in memory: one being rendered, one being encoded.

use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::thread::JoinHandle;

use crate::framebuffer::RenderError;
use crate::streamed::PngStream;

/// What the encoder thread is sent.
enum Msg {
    /// The first `n` pixels of the buffer are the next rows.
    Band(Vec<u32>, usize),
    /// Every row is in: finish the file.
    Finish,
}

/// The encoder thread of one PNG, and the band buffers going to it and coming back.
pub struct BandEncoder {
    /// `None` once dropped (the thread then stops).
    to: Option<SyncSender<Msg>>,
    back: Option<Receiver<Vec<u32>>>,
    /// The buffer to hand out at the first band (the second one).
    spare: Option<Vec<u32>>,
    thread: Option<JoinHandle<Result<(), RenderError>>>,
}

impl BandEncoder {
    /// Starts the thread writing `png`; `spare` is a second band buffer as large as the one
    /// the caller renders into. Dropped without [`BandEncoder::finish`] (an error on the
    /// caller's side), the thread drops the stream and its temporary file goes with it.
    pub fn spawn(png: PngStream, spare: Vec<u32>) -> Result<BandEncoder, RenderError> {
        let (to, from) = sync_channel::<Msg>(1);
        let (give_back, back) = sync_channel(1);
        let path = png.path().to_path_buf();
        let thread = std::thread::Builder::new()
            .name("png encoder".into())
            .spawn(move || encode(png, from, give_back))
            .map_err(|e| RenderError::Png {
                path: path.display().to_string(),
                source: e.into(),
            })?;
        Ok(BandEncoder {
            to: Some(to),
            back: Some(back),
            spare: Some(spare),
            thread: Some(thread),
        })
    }

    /// Hands `band[..n]` (whole rows, the next ones) to the encoder and returns a buffer to
    /// render the following band into, waiting until the encoder is done with it.
    pub fn write(&mut self, band: Vec<u32>, n: usize) -> Result<Vec<u32>, RenderError> {
        if self.sender().send(Msg::Band(band, n)).is_err() {
            return Err(self.join());
        }
        if let Some(b) = self.spare.take() {
            return Ok(b);
        }
        let back = self.back.as_ref().expect("alive until dropped").recv();
        back.map_err(|_| self.join())
    }

    /// Waits for the last band to be encoded and the file finished (renamed to its path).
    pub fn finish(mut self) -> Result<(), RenderError> {
        if self.sender().send(Msg::Finish).is_err() {
            return Err(self.join());
        }
        let thread = self.thread.take().expect("joined once");
        thread
            .join()
            .unwrap_or_else(|p| std::panic::resume_unwind(p))
    }

    fn sender(&self) -> &SyncSender<Msg> {
        self.to.as_ref().expect("alive until dropped")
    }

    /// The error the encoder thread stopped with.
    fn join(&mut self) -> RenderError {
        let thread = self.thread.take().expect("joined once");
        match thread
            .join()
            .unwrap_or_else(|p| std::panic::resume_unwind(p))
        {
            Err(e) => e,
            Ok(()) => unreachable!("the encoder ends early only on an error"),
        }
    }
}

impl Drop for BandEncoder {
    /// Unfinished: closes both channels and waits for the thread, so that the temporary file
    /// is gone when this returns.
    fn drop(&mut self) {
        self.to = None;
        self.back = None;
        if let Some(t) = self.thread.take() {
            t.join().ok();
        }
    }
}

/// The encoder thread: bands written in order and their buffers given back.
fn encode(
    mut png: PngStream,
    from: Receiver<Msg>,
    give_back: SyncSender<Vec<u32>>,
) -> Result<(), RenderError> {
    for msg in from {
        match msg {
            Msg::Band(band, n) => {
                png.write_rows(&band[..n])?;
                // The caller may have stopped waiting (its error): then stop too.
                if give_back.send(band).is_err() {
                    return Ok(());
                }
            }
            Msg::Finish => return png.finish(),
        }
    }
    Ok(()) // the caller dropped the encoder: `png` is dropped unfinished, its file removed
}
