//! PDB: ATOM/HETATM records (fixed columns), MODEL/ENDMDL frames, CRYST1 cell, CONECT bonds.
//!
//! Elements come from columns 77-78; if blank or invalid, from the atom name (columns 13-16,
//! PDB convention: a name starting in column 14 has a one-letter element, a name starting in
//! column 13 a two-letter one, except hydrogens like `HD21`; `ATOM` records always get a
//! one-letter element since CHARMM and others left-justify names like `CA`). Frames end at `ENDMDL`, `END`
//! or end of file. `CONECT` records that come before the frame ends are kept as
//! [`crate::Molecule::file_bonds`]. Scalars: `occupancy`, `bfactor`.

use super::lex::{parse_f32, parse_i64, trim, SymbolCache};
use super::{FrameParser, LineReader, ReadError};
use crate::{elements, Cell, Molecule};
use std::collections::HashMap;

#[derive(Default)]
pub(crate) struct PdbParser {
    syms: SymbolCache,
    warned_names: Vec<Vec<u8>>,
}

fn cols(line: &[u8], a: usize, b: usize) -> &[u8] {
    let b = b.min(line.len());
    if a >= b {
        return &[];
    }
    trim(&line[a..b])
}

fn element_from_name(name_field: &[u8], hetatm: bool) -> Option<u8> {
    // name_field = columns 13-16 untrimmed.
    let f = |b: &[u8]| std::str::from_utf8(b).ok().and_then(elements::by_symbol);
    let first = *name_field.first()?;
    let letters: Vec<u8> = name_field
        .iter()
        .copied()
        .filter(|c| c.is_ascii_alphabetic())
        .collect();
    if letters.is_empty() {
        return None;
    }
    // ATOM records are polymer residues (H, C, N, O, S, P): one letter even when the name is
    // left-justified (CHARMM style, e.g. "CA  " = C-alpha).
    if first == b' ' || first.is_ascii_digit() || !hetatm {
        return f(&letters[..1]);
    }
    if letters[0].eq_ignore_ascii_case(&b'H') && name_field.len() >= 4 {
        return Some(1);
    }
    if letters.len() >= 2 {
        if let Some(z) = f(&letters[..2]) {
            return Some(z);
        }
    }
    f(&letters[..1])
}

impl FrameParser for PdbParser {
    fn next_frame(&mut self, r: &mut LineReader) -> Result<Option<Molecule>, ReadError> {
        let mut m = Molecule::default();
        let mut occ = Vec::new();
        let mut bfac = Vec::new();
        let mut serials: HashMap<i64, u32> = HashMap::new();
        let mut bonds: Vec<[u32; 2]> = Vec::new();
        let mut conect_seen = false;
        let mut ended = false;
        let path = r.path.clone();
        while let Some((ln, line)) = r.next_line()? {
            let rec = &line[..line.len().min(6)];
            if rec.starts_with(b"ATOM") || rec.starts_with(b"HETATM") {
                if line.len() < 54 {
                    let l = line.to_vec();
                    return Err(r.error(
                        ln,
                        "an ATOM/HETATM record with x, y, z in columns 31-54",
                        &l,
                    ));
                }
                let mut p = [0f32; 3];
                for (k, pk) in p.iter_mut().enumerate() {
                    let t = cols(line, 30 + 8 * k, 38 + 8 * k);
                    match parse_f32(t) {
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
                            return Err(r.error(
                                ln,
                                &format!("a number in columns {}-{}", 31 + 8 * k, 38 + 8 * k),
                                &t,
                            ));
                        }
                    }
                }
                let el = cols(line, 76, 78);
                let z = if !el.is_empty() && el.iter().all(|c| c.is_ascii_alphabetic()) {
                    self.syms.lookup(el, &path, ln)
                } else {
                    let name = &line[12.min(line.len())..16.min(line.len())];
                    match element_from_name(name, rec.starts_with(b"HETATM")) {
                        Some(z) => z,
                        None => {
                            if !self.warned_names.iter().any(|n| n == name)
                                && self.warned_names.len() < 100
                            {
                                self.warned_names.push(name.to_vec());
                                self.syms.warnings.push(format!(
                                    "{}:{ln}: no element for atom name {}; treated as unknown (Z = 0)",
                                    path.display(),
                                    super::lex::show(name)
                                ));
                            }
                            0
                        }
                    }
                };
                if let Some(s) = parse_i64(cols(line, 6, 11)) {
                    serials.entry(s).or_insert(m.len() as u32);
                }
                occ.push(parse_f32(cols(line, 54, 60)).unwrap_or(1.0));
                bfac.push(parse_f32(cols(line, 60, 66)).unwrap_or(0.0));
                m.push(p, z);
            } else if rec.starts_with(b"CONECT") {
                conect_seen = true;
                let a = parse_i64(cols(line, 6, 11));
                for k in 0..4 {
                    let b = parse_i64(cols(line, 11 + 5 * k, 16 + 5 * k));
                    if let (Some(a), Some(b)) = (a, b) {
                        if let (Some(&i), Some(&j)) = (serials.get(&a), serials.get(&b)) {
                            if i != j {
                                bonds.push([i.min(j), i.max(j)]);
                            }
                        }
                    }
                }
            } else if rec.starts_with(b"CRYST1") {
                let v: Vec<f64> = [(6, 15), (15, 24), (24, 33), (33, 40), (40, 47), (47, 54)]
                    .iter()
                    .filter_map(|&(a, b)| parse_f32(cols(line, a, b)).map(f64::from))
                    .collect();
                if v.len() == 6
                    && v.iter().all(|x| x.is_finite())
                    && !(v[0] <= 1.0 && v[1] <= 1.0 && v[2] <= 1.0)
                {
                    m.cell = cryst1_cell(&v);
                }
            } else if rec.starts_with(b"ENDMDL")
                || rec == b"END"
                || (rec.starts_with(b"END")
                    && rec.len() >= 3
                    && rec[3..].iter().all(|c| *c == b' '))
            {
                if m.is_empty() && !conect_seen {
                    continue;
                }
                ended = true;
                break;
            }
        }
        let _ = ended;
        if m.is_empty() {
            return Ok(None);
        }
        m.scalars = vec![("occupancy".into(), occ), ("bfactor".into(), bfac)];
        if conect_seen {
            bonds.sort_unstable();
            bonds.dedup();
            m.file_bonds = Some(bonds);
        }
        Ok(Some(m))
    }

    fn warnings(&self) -> &[String] {
        &self.syms.warnings
    }
}

/// Cell vectors from CRYST1 `a b c alpha beta gamma` (Å, degrees), standard PDB orientation.
fn cryst1_cell(v: &[f64]) -> Option<Cell> {
    let (a, b, c) = (v[0], v[1], v[2]);
    let (al, be, ga) = (v[3].to_radians(), v[4].to_radians(), v[5].to_radians());
    let (ca, cb, cg, sg) = (al.cos(), be.cos(), ga.cos(), ga.sin());
    if sg.abs() < 1e-6 {
        return None;
    }
    let cy = c * (ca - cb * cg) / sg;
    let cz2 = c * c - (c * cb) * (c * cb) - cy * cy;
    if cz2 <= 0.0 {
        return None;
    }
    Some(Cell {
        origin: [0.0; 3],
        edges: [
            [a as f32, 0.0, 0.0],
            [(b * cg) as f32, (b * sg) as f32, 0.0],
            [(c * cb) as f32, cy as f32, cz2.sqrt() as f32],
        ],
        pbc: [true; 3],
    })
}
