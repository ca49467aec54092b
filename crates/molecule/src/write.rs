//! Writers: extended XYZ and LAMMPS text dump (for `bnsview generate`).

use crate::{elements, Molecule};
use std::io::{self, Write};

fn lattice(m: &Molecule) -> String {
    match &m.cell {
        Some(c) => {
            let e = c.edges;
            format!(
                "Lattice=\"{} {} {} {} {} {} {} {} {}\" ",
                e[0][0], e[0][1], e[0][2], e[1][0], e[1][1], e[1][2], e[2][0], e[2][1], e[2][2]
            )
        }
        None => String::new(),
    }
}

/// Write one frame as extended XYZ (`Properties=species:S:1:pos:R:3`, positions in Å with
/// 5 decimals).
pub fn write_xyz<W: Write + ?Sized>(w: &mut W, m: &Molecule, comment: &str) -> io::Result<()> {
    writeln!(w, "{}", m.len())?;
    writeln!(
        w,
        "{}Properties=species:S:1:pos:R:3 comment=\"{}\"",
        lattice(m),
        comment.replace('"', "'")
    )?;
    for i in 0..m.len() {
        writeln!(
            w,
            "{} {:.5} {:.5} {:.5}",
            elements::element(m.elements[i]).symbol,
            m.x[i],
            m.y[i],
            m.z[i]
        )?;
    }
    Ok(())
}

/// Write one frame as a LAMMPS text dump with columns `id type element x y z`; types are
/// numbered by ascending atomic number. The box is the cell if any, else the bounds padded
/// by 1 Å (non-periodic `ff`).
pub fn write_lammps_dump<W: Write + ?Sized>(
    w: &mut W,
    m: &Molecule,
    timestep: u64,
) -> io::Result<()> {
    let counts = m.element_counts();
    let mut type_of = [0u32; 256];
    for (t, (z, _)) in counts.iter().enumerate() {
        type_of[*z as usize] = t as u32 + 1;
    }
    writeln!(
        w,
        "ITEM: TIMESTEP\n{timestep}\nITEM: NUMBER OF ATOMS\n{}",
        m.len()
    )?;
    match &m.cell {
        Some(c) if c.edges[0][1] == 0.0 && c.edges[0][2] == 0.0 && c.edges[1][2] == 0.0 => {
            let o = c.origin;
            let e = c.edges;
            let (xy, xz, yz) = (e[1][0], e[2][0], e[2][1]);
            let (xlo, xhi) = (o[0], o[0] + e[0][0]);
            let (ylo, yhi) = (o[1], o[1] + e[1][1]);
            let (zlo, zhi) = (o[2], o[2] + e[2][2]);
            if xy == 0.0 && xz == 0.0 && yz == 0.0 {
                writeln!(
                    w,
                    "ITEM: BOX BOUNDS pp pp pp\n{xlo} {xhi}\n{ylo} {yhi}\n{zlo} {zhi}"
                )?;
            } else {
                let xlob = xlo + 0f32.min(xy).min(xz).min(xy + xz);
                let xhib = xhi + 0f32.max(xy).max(xz).max(xy + xz);
                let ylob = ylo + 0f32.min(yz);
                let yhib = yhi + 0f32.max(yz);
                writeln!(
                    w,
                    "ITEM: BOX BOUNDS xy xz yz pp pp pp\n{xlob} {xhib} {xy}\n{ylob} {yhib} {xz}\n{zlo} {zhi} {yz}"
                )?;
            }
        }
        _ => {
            let (lo, hi) = m.bounds();
            writeln!(
                w,
                "ITEM: BOX BOUNDS ff ff ff\n{} {}\n{} {}\n{} {}",
                lo[0] - 1.0,
                hi[0] + 1.0,
                lo[1] - 1.0,
                hi[1] + 1.0,
                lo[2] - 1.0,
                hi[2] + 1.0
            )?;
        }
    }
    writeln!(w, "ITEM: ATOMS id type element x y z")?;
    for i in 0..m.len() {
        let z = m.elements[i];
        writeln!(
            w,
            "{} {} {} {:.5} {:.5} {:.5}",
            i + 1,
            type_of[z as usize],
            elements::element(z).symbol,
            m.x[i],
            m.y[i],
            m.z[i]
        )?;
    }
    Ok(())
}
