//! GROMACS `.gro`: title, atom count, fixed-column atom lines (positions in nm, converted to
//! Å), box line; several frames may follow each other. Elements are guessed from the atom
//! name (columns 11-15). Field width of the coordinates is detected from the decimal points
//! (GROMACS writes `%8.3f` by default, other precisions are allowed).

use super::lex::{parse_f32, parse_f64, parse_usize, trim};
use super::{FrameParser, LineReader, ReadError};
use crate::{elements, Cell, Molecule};

#[derive(Default)]
pub(crate) struct GroParser {
    warnings: Vec<String>,
    warned: Vec<Vec<u8>>,
}

impl FrameParser for GroParser {
    fn next_frame(&mut self, r: &mut LineReader) -> Result<Option<Molecule>, ReadError> {
        // Title (skip blank lines between frames).
        loop {
            let Some((_, l)) = r.next_line()? else {
                return Ok(None);
            };
            if !trim(l).is_empty() {
                break;
            }
        }
        let (ln, l) = r.expect_line("the number of atoms")?;
        let t = trim(l);
        let n = match parse_usize(t) {
            Some(n) if n <= u32::MAX as usize => n,
            _ => {
                let t = t.to_vec();
                return Err(r.error(ln, "the number of atoms (an integer)", &t));
            }
        };
        let mut m = Molecule::with_capacity(n.min(1 << 26));
        let mut width = 0usize;
        let path = r.path.clone();
        for i in 0..n {
            let Some((ln, line)) = r.next_line()? else {
                let next = r.line_no() + 1;
                return Err(r.error(
                    next,
                    &format!("{n} atom lines, got {i}"),
                    b"end of file (truncated frame)",
                ));
            };
            if width == 0 {
                // Distance between the first two decimal points after column 20.
                let dots: Vec<usize> = line
                    .iter()
                    .enumerate()
                    .skip(20)
                    .filter(|(_, c)| **c == b'.')
                    .map(|(k, _)| k)
                    .take(2)
                    .collect();
                width = if dots.len() == 2 {
                    dots[1] - dots[0]
                } else {
                    8
                };
                if !(4..=30).contains(&width) {
                    width = 8;
                }
            }
            if line.len() < 20 + 3 * width {
                let l = line.to_vec();
                return Err(r.error(
                    ln,
                    &format!("an atom line with x, y, z in columns 21-{}", 20 + 3 * width),
                    &l,
                ));
            }
            let mut p = [0f32; 3];
            for (k, pk) in p.iter_mut().enumerate() {
                let t = trim(&line[20 + k * width..20 + (k + 1) * width]);
                // Scale nm → Å first, then check: 1e39 nm is finite in f64 but inf in f32 Å.
                match parse_f64(t).map(|v| (v * 10.0) as f32) {
                    Some(v) if v.is_finite() => *pk = v,
                    Some(_) => {
                        let t = t.to_vec();
                        return Err(r.error(
                            ln,
                            "a finite coordinate (NaN/inf are not allowed)",
                            &t,
                        ));
                    }
                    None => {
                        let t = t.to_vec();
                        return Err(r.error(ln, "a number (coordinate in nm)", &t));
                    }
                }
            }
            let name = trim(&line[10..15]);
            let z = match std::str::from_utf8(name)
                .ok()
                .and_then(elements::guess_from_name)
            {
                Some(z) => z,
                None => {
                    if !self.warned.iter().any(|w| w == name) && self.warned.len() < 100 {
                        self.warned.push(name.to_vec());
                        self.warnings.push(format!(
                            "{}:{ln}: no element for atom name {}; treated as unknown (Z = 0)",
                            path.display(),
                            super::lex::show(name)
                        ));
                    }
                    0
                }
            };
            m.push(p, z);
        }
        let (ln, l) = r.expect_line("the box line")?;
        // Scaled to Å before the finiteness check.
        let nums: Vec<f32> = super::lex::fields(l)
            .map_while(parse_f32)
            .map(|v| v * 10.0)
            .collect();
        if (nums.len() != 3 && nums.len() != 9) || nums.iter().any(|x| !x.is_finite()) {
            let l = l.to_vec();
            return Err(r.error(ln, "the box line (3 or 9 numbers in nm, finite in Å)", &l));
        }
        let g = |i: usize| nums.get(i).copied().unwrap_or(0.0);
        if nums.iter().any(|&x| x != 0.0) {
            m.cell = Some(Cell {
                origin: [0.0; 3],
                edges: [[g(0), g(3), g(4)], [g(5), g(1), g(6)], [g(7), g(8), g(2)]],
                pbc: [true; 3],
            });
        }
        Ok(Some(m))
    }

    fn warnings(&self) -> &[String] {
        &self.warnings
    }
}
