//! Which frames of a trajectory to render: `all` or `A:B[:STEP]`.

use std::fmt;
use std::str::FromStr;

/// Frames of a trajectory, 0-based: `all`, or from `start` up to (not including) `end` every
/// `step`-th (`end` `None`: to the last frame).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameRange {
    /// First frame.
    pub start: usize,
    /// One past the last frame (`None`: to the end of the file).
    pub end: Option<usize>,
    /// Distance between rendered frames (≥ 1).
    pub step: usize,
}

impl FrameRange {
    /// Every frame.
    pub const ALL: FrameRange = FrameRange {
        start: 0,
        end: None,
        step: 1,
    };

    /// Whether frame `k` is rendered.
    pub fn contains(&self, k: usize) -> bool {
        k >= self.start
            && self.end.is_none_or(|e| k < e)
            && (k - self.start).is_multiple_of(self.step)
    }

    /// Whether no frame after `k` can be rendered.
    pub fn done_after(&self, k: usize) -> bool {
        self.end.is_some_and(|e| k + 1 >= e)
    }
}

/// Why a frame range did not parse.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
#[error("--frames {0:?}: expected all or A:B[:STEP] (frames A up to but not including B, every STEP-th; A or B may be left out), e.g. 0:100:10")]
pub struct FrameRangeError(pub String);

impl FromStr for FrameRange {
    type Err = FrameRangeError;
    fn from_str(s: &str) -> Result<FrameRange, FrameRangeError> {
        let bad = || FrameRangeError(s.to_string());
        if s.trim() == "all" {
            return Ok(FrameRange::ALL);
        }
        let parts: Vec<&str> = s.split(':').map(str::trim).collect();
        if !(2..=3).contains(&parts.len()) {
            return Err(bad());
        }
        let num = |p: &str| -> Result<Option<usize>, FrameRangeError> {
            if p.is_empty() {
                Ok(None)
            } else {
                p.parse().map(Some).map_err(|_| bad())
            }
        };
        let start = num(parts[0])?.unwrap_or(0);
        let end = num(parts[1])?;
        let step = match parts.get(2) {
            Some(p) => num(p)?.unwrap_or(1),
            None => 1,
        };
        if step == 0 || end.is_some_and(|e| e <= start) {
            return Err(bad());
        }
        Ok(FrameRange { start, end, step })
    }
}

impl fmt::Display for FrameRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if *self == FrameRange::ALL {
            return write!(f, "all");
        }
        write!(f, "{}:", self.start)?;
        if let Some(e) = self.end {
            write!(f, "{e}")?;
        }
        if self.step != 1 {
            write!(f, ":{}", self.step)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_parse_print_and_select() {
        let r: FrameRange = "2:11:3".parse().unwrap();
        let picked: Vec<usize> = (0..20).filter(|&k| r.contains(k)).collect();
        assert_eq!(picked, [2, 5, 8]);
        assert_eq!(r.to_string(), "2:11:3");
        assert_eq!("all".parse::<FrameRange>().unwrap(), FrameRange::ALL);
        let open: FrameRange = "5:".parse().unwrap();
        assert!(open.contains(1000) && !open.contains(4));
        assert_eq!(":3".parse::<FrameRange>().unwrap().end, Some(3));
        for bad in ["", "x", "3", "5:2", "1:2:0", "1:2:3:4", "-1:2", "a:b"] {
            assert!(bad.parse::<FrameRange>().is_err(), "{bad:?}");
        }
    }
}
