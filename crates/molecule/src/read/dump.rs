//! LAMMPS text dump (`dump atom`/`dump custom`): any column order, orthogonal and triclinic
//! boxes, scaled/unwrapped coordinates, many timesteps. Atoms are sorted by `id` so frames
//! line up.
//!
//! Coordinates are taken from the first available of `x y z`, `xu yu zu`, `xs ys zs`,
//! `xsu ysu zsu` (the same preference as ASE); with `xu yu zu` or `xsu ysu zsu` the frame is
//! marked [`Molecule::unwrapped`], so image flags `ix iy iz` are not applied on top
//! ([`crate::unwrap`]). Elements come from an `element` column, else
//! from [`super::ReadOptions::types`], else from a `mass` column (nearest standard weight),
//! else unknown (Z = 0, with a warning). Every other column (`id`, `type`, `q`, `mol`,
//! `mass`, `ix iy iz`, and coordinate columns not used for the positions, e.g. `xu` when `x`
//! is there) is kept as a per-atom scalar of that name; `timestep` is not stored.

use super::lex::{parse_f32, parse_f64, parse_i64, parse_usize, split_spans, trim, SymbolCache};
use super::{FrameParser, LineReader, ReadError, ReadOptions};
use crate::{elements, Cell, Molecule};

pub(crate) struct DumpParser {
    opts: ReadOptions,
    syms: SymbolCache,
    warned_types: Vec<i64>,
}

impl DumpParser {
    pub(crate) fn new(opts: ReadOptions) -> DumpParser {
        DumpParser {
            opts,
            syms: SymbolCache::default(),
            warned_types: Vec::new(),
        }
    }
}

struct Header {
    n: usize,
    /// lo, hi, tilt (xy, xz, yz) as written in BOX BOUNDS.
    cell: Option<Cell>,
    columns: Vec<String>,
}

fn item_line(r: &mut LineReader, what: &str) -> Result<(u64, Vec<u8>), ReadError> {
    let (ln, l) = r.expect_line(what)?;
    Ok((ln, trim(l).to_vec()))
}

fn read_header(r: &mut LineReader) -> Result<Option<Header>, ReadError> {
    // ITEM: TIMESTEP (skip blank lines before it)
    let (ln, first) = loop {
        let Some((ln, l)) = r.next_line()? else {
            return Ok(None);
        };
        let t = trim(l);
        if !t.is_empty() {
            break (ln, t.to_vec());
        }
    };
    if !first.starts_with(b"ITEM: TIMESTEP") {
        return Err(r.error(ln, "'ITEM: TIMESTEP'", &first));
    }
    let mut n = None;
    let mut cell = None;
    loop {
        let (ln, item) = item_line(r, "an 'ITEM:' line")?;
        if !item.starts_with(b"ITEM:") {
            // Timestep value or unknown item payload: skip.
            continue;
        }
        let rest = trim(&item[5..]).to_vec();
        if rest.starts_with(b"NUMBER OF ATOMS") {
            let (ln, v) = item_line(r, "the number of atoms")?;
            n = Some(
                parse_usize(&v)
                    .filter(|&n| n <= u32::MAX as usize)
                    .ok_or_else(|| r.error(ln, "the number of atoms (an integer)", &v))?,
            );
        } else if rest.starts_with(b"BOX BOUNDS") {
            let triclinic = rest.windows(2).any(|w| w == b"xy");
            let words: Vec<&[u8]> = super::lex::fields(&rest[10..]).collect();
            let flags: Vec<&[u8]> = if triclinic {
                words.iter().skip(3).copied().collect()
            } else {
                words
            };
            let mut pbc = [true; 3];
            for (k, f) in flags.iter().take(3).enumerate() {
                pbc[k] = f.starts_with(b"p");
            }
            let mut v = [[0f64; 3]; 3];
            for row in v.iter_mut() {
                let (ln, l) = item_line(r, "a BOX BOUNDS line 'lo hi [tilt]'")?;
                let nums: Vec<f64> = super::lex::fields(&l).map_while(parse_f64).collect();
                if nums.len() < if triclinic { 3 } else { 2 } || nums.iter().any(|x| !x.is_finite())
                {
                    return Err(r.error(
                        ln,
                        if triclinic {
                            "'lo hi tilt' (3 finite numbers)"
                        } else {
                            "'lo hi' (2 finite numbers)"
                        },
                        &l,
                    ));
                }
                row[0] = nums[0];
                row[1] = nums[1];
                row[2] = if triclinic { nums[2] } else { 0.0 };
            }
            let (xy, xz, yz) = (v[0][2], v[1][2], v[2][2]);
            let xlo = v[0][0] - 0f64.min(xy).min(xz).min(xy + xz);
            let xhi = v[0][1] - 0f64.max(xy).max(xz).max(xy + xz);
            let ylo = v[1][0] - 0f64.min(yz);
            let yhi = v[1][1] - 0f64.max(yz);
            let (zlo, zhi) = (v[2][0], v[2][1]);
            cell = Some(Cell {
                origin: [xlo as f32, ylo as f32, zlo as f32],
                edges: [
                    [(xhi - xlo) as f32, 0.0, 0.0],
                    [xy as f32, (yhi - ylo) as f32, 0.0],
                    [xz as f32, yz as f32, (zhi - zlo) as f32],
                ],
                pbc,
            });
        } else if rest.starts_with(b"ATOMS") {
            let columns: Vec<String> = super::lex::fields(&rest[5..])
                .map(|c| String::from_utf8_lossy(c).into_owned())
                .collect();
            let Some(n) = n else {
                return Err(r.error(ln, "'ITEM: NUMBER OF ATOMS' before 'ITEM: ATOMS'", &item));
            };
            if columns.is_empty() {
                return Err(r.error(ln, "column names after 'ITEM: ATOMS'", &item));
            }
            return Ok(Some(Header { n, cell, columns }));
        }
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Coords {
    Cart,
    Scaled,
}

impl FrameParser for DumpParser {
    fn next_frame(&mut self, r: &mut LineReader) -> Result<Option<Molecule>, ReadError> {
        let Some(h) = read_header(r)? else {
            return Ok(None);
        };
        let header_line = r.line_no();
        let col = |name: &str| h.columns.iter().position(|c| c == name);
        let mut pos = None;
        for (names, kind, unwrapped) in [
            (["x", "y", "z"], Coords::Cart, false),
            (["xu", "yu", "zu"], Coords::Cart, true),
            (["xs", "ys", "zs"], Coords::Scaled, false),
            (["xsu", "ysu", "zsu"], Coords::Scaled, true),
        ] {
            if let (Some(a), Some(b), Some(c)) = (col(names[0]), col(names[1]), col(names[2])) {
                pos = Some(([a, b, c], kind, unwrapped));
                break;
            }
        }
        let Some((pc, kind, unwrapped)) = pos else {
            let cols = h.columns.join(" ");
            return Err(r.error(
                header_line,
                "coordinate columns (x y z, xu yu zu, xs ys zs or xsu ysu zsu)",
                cols.as_bytes(),
            ));
        };
        if kind == Coords::Scaled && h.cell.is_none() {
            return Err(r.error(
                header_line,
                "'ITEM: BOX BOUNDS' before scaled coordinates",
                b"no box",
            ));
        }
        let id_col = col("id");
        let type_col = col("type");
        let elem_col = col("element");
        let mass_col = col("mass");
        // The coordinate columns used for the positions, and `element`, are not scalars; the
        // other coordinate columns (`xu` when `x` is there, …) are, so `--color xu` works.
        let scalar_cols: Vec<(String, usize)> = h
            .columns
            .iter()
            .enumerate()
            .filter(|(i, c)| !pc.contains(i) && c.as_str() != "element")
            .map(|(i, c)| (c.clone(), i))
            .collect();
        let n = h.n;
        let ncols = h.columns.len();
        let cap = n.min(1 << 26);
        let mut m = Molecule::with_capacity(cap);
        m.cell = h.cell;
        m.unwrapped = unwrapped;
        let mut scal: Vec<Vec<f32>> = scalar_cols
            .iter()
            .map(|_| Vec::with_capacity(cap))
            .collect();
        let mut ids: Vec<i64> = Vec::with_capacity(if id_col.is_some() { cap } else { 0 });
        let mut type_z: Vec<Option<u8>> = Vec::new();
        let mut spans = Vec::with_capacity(ncols);
        let path = r.path.clone();
        let (h_mat, origin) = match &h.cell {
            Some(c) => (c.matrix(), c.origin.map(f64::from)),
            None => ([[0.0; 3]; 3], [0.0; 3]),
        };
        for i in 0..n {
            let Some((ln, line)) = r.next_line()? else {
                let next = r.line_no() + 1;
                return Err(r.error(
                    next,
                    &format!("{n} atom lines (NUMBER OF ATOMS), got {i}"),
                    b"end of file (truncated frame)",
                ));
            };
            split_spans(line, &mut spans);
            if spans.len() < ncols {
                let l = line.to_vec();
                return Err(r.error(
                    ln,
                    &format!("{ncols} columns ({})", h.columns.join(" ")),
                    &l,
                ));
            }
            let f = |k: usize| &line[spans[k].0..spans[k].1];
            let mut p = [0f64; 3];
            for k in 0..3 {
                let t = f(pc[k]);
                // Cartesian columns are stored as f32 anyway; scaled ones need f64.
                let v = if kind == Coords::Cart {
                    parse_f32(t).map(f64::from)
                } else {
                    parse_f64(t)
                };
                match v {
                    Some(v) if v.is_finite() => p[k] = v,
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
                        return Err(r.error(ln, "a number (coordinate)", &t));
                    }
                }
            }
            if kind == Coords::Scaled {
                let s = p;
                for (k, pk) in p.iter_mut().enumerate() {
                    *pk = origin[k] + h_mat[k][0] * s[0] + h_mat[k][1] * s[1] + h_mat[k][2] * s[2];
                }
                // Scaled → Cartesian first, then check the f32 result is finite.
                if p.iter().any(|&v| !(v as f32).is_finite()) {
                    let l = line.to_vec();
                    return Err(r.error(
                        ln,
                        "scaled coordinates giving a finite position in Å",
                        &l,
                    ));
                }
            }
            if let Some(c) = id_col {
                match parse_i64(f(c)) {
                    Some(v) => ids.push(v),
                    None => {
                        let t = f(c).to_vec();
                        return Err(r.error(ln, "an integer atom id", &t));
                    }
                }
            }
            for (v, (_, c)) in scal.iter_mut().zip(&scalar_cols) {
                match parse_f32(f(*c)) {
                    Some(x) => v.push(x),
                    None => {
                        let t = f(*c).to_vec();
                        return Err(r.error(
                            ln,
                            &format!("a number in column '{}'", h.columns[*c]),
                            &t,
                        ));
                    }
                }
            }
            let z = if let Some(c) = elem_col {
                self.syms.lookup(f(c), &path, ln)
            } else if let Some(c) = type_col {
                let t = match parse_i64(f(c)) {
                    Some(t) if (0..1 << 20).contains(&t) => t as usize,
                    _ => {
                        let t = f(c).to_vec();
                        return Err(r.error(ln, "an integer atom type", &t));
                    }
                };
                if t >= type_z.len() {
                    type_z.resize(t + 1, None);
                }
                match type_z[t] {
                    Some(z) => z,
                    None => {
                        let z = self.opts.type_element(t as u32).or_else(|| {
                            mass_col
                                .and_then(|mc| parse_f32(f(mc)))
                                .and_then(elements::by_mass)
                        });
                        let z = match z {
                            Some(z) => z,
                            None => {
                                if !self.warned_types.contains(&(t as i64)) {
                                    self.warned_types.push(t as i64);
                                    self.syms.warnings.push(format!(
                                        "{}:{ln}: atom type {t} has no element (no element/mass column, not in --types); treated as unknown (Z = 0)",
                                        path.display()
                                    ));
                                }
                                0
                            }
                        };
                        type_z[t] = Some(z);
                        z
                    }
                }
            } else {
                0
            };
            m.push([p[0] as f32, p[1] as f32, p[2] as f32], z);
        }
        m.scalars = scalar_cols.into_iter().map(|(n, _)| n).zip(scal).collect();
        if !ids.is_empty() && !ids.windows(2).all(|w| w[0] <= w[1]) {
            let mut perm: Vec<u32> = (0..n as u32).collect();
            perm.sort_unstable_by_key(|&i| ids[i as usize]);
            // Free the ids before permuting (peak memory ≤ ~1.4× the final arrays).
            drop(ids);
            apply_perm(&mut m, &perm);
        }
        Ok(Some(m))
    }

    fn skip_frame(&mut self, r: &mut LineReader) -> Result<bool, ReadError> {
        let Some(h) = read_header(r)? else {
            return Ok(false);
        };
        for i in 0..h.n {
            if r.next_line()?.is_none() {
                let next = r.line_no() + 1;
                return Err(r.error(
                    next,
                    &format!("{} atom lines (NUMBER OF ATOMS), got {i}", h.n),
                    b"end of file (truncated frame)",
                ));
            }
        }
        Ok(true)
    }

    fn warnings(&self) -> &[String] {
        &self.syms.warnings
    }
}

/// Reorder all per-atom arrays: new atom `k` = old atom `perm[k]`.
pub(crate) fn apply_perm(m: &mut Molecule, perm: &[u32]) {
    fn permute<T: Copy>(v: &mut Vec<T>, perm: &[u32]) {
        if v.len() == perm.len() {
            *v = perm.iter().map(|&i| v[i as usize]).collect();
        }
    }
    permute(&mut m.x, perm);
    permute(&mut m.y, perm);
    permute(&mut m.z, perm);
    permute(&mut m.elements, perm);
    for (_, v) in m.scalars.iter_mut() {
        permute(v, perm);
    }
}
