//! Periodic table for Z = 1..=103 plus "unknown" (Z = 0).
//!
//! Sources (values were generated from the tables shipped with ASE 3.29):
//! - covalent radius: Cordero et al., *Dalton Trans.* 2008, 2832 (Z = 1..=96; carbon uses the
//!   sp3 value 0.76 Å). Z = 97..=103 have no Cordero value and use a 2.00 Å placeholder.
//! - van der Waals radius: Alvarez, *Dalton Trans.* 2013, 42, 8617. Elements without a value
//!   (Z ≥ 100) use 2.00 Å.
//! - colour: Jmol CPK colours (sRGB, 0-255).
//! - mass: standard atomic weight (g/mol = u), used to guess elements from LAMMPS `Masses`.
//!
//! "Unknown" (Z = 0, symbol `X`) gets a covalent radius of 0.75 Å (so it still bonds like a
//! light element), a vdW radius of 1.70 Å and a deep-pink colour so it stands out.

/// One chemical element.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Element {
    /// Chemical symbol, e.g. `"Al"`; `"X"` for unknown.
    pub symbol: &'static str,
    /// Atomic number Z (0 = unknown).
    pub number: u8,
    /// Covalent radius in Å (Cordero 2008).
    pub covalent_radius: f32,
    /// Van der Waals radius in Å (Alvarez 2013).
    pub vdw_radius: f32,
    /// Jmol CPK colour, sRGB 0-255.
    pub color: [u8; 3],
    /// Standard atomic weight in u (0 for unknown).
    pub mass: f32,
}

/// Largest atomic number in the table.
pub const MAX_Z: u8 = 103;

// Values are copied verbatim from the published tables.
#[allow(clippy::excessive_precision)]
static TABLE: [Element; 104] = [
    Element {
        symbol: "X",
        number: 0,
        covalent_radius: 0.75,
        vdw_radius: 1.70,
        color: [255, 20, 147],
        mass: 0.0000,
    },
    Element {
        symbol: "H",
        number: 1,
        covalent_radius: 0.31,
        vdw_radius: 1.20,
        color: [255, 255, 255],
        mass: 1.0080,
    },
    Element {
        symbol: "He",
        number: 2,
        covalent_radius: 0.28,
        vdw_radius: 1.43,
        color: [217, 255, 255],
        mass: 4.0026,
    },
    Element {
        symbol: "Li",
        number: 3,
        covalent_radius: 1.28,
        vdw_radius: 2.12,
        color: [204, 128, 255],
        mass: 6.9400,
    },
    Element {
        symbol: "Be",
        number: 4,
        covalent_radius: 0.96,
        vdw_radius: 1.98,
        color: [194, 255, 0],
        mass: 9.0122,
    },
    Element {
        symbol: "B",
        number: 5,
        covalent_radius: 0.84,
        vdw_radius: 1.91,
        color: [255, 181, 181],
        mass: 10.8100,
    },
    Element {
        symbol: "C",
        number: 6,
        covalent_radius: 0.76,
        vdw_radius: 1.77,
        color: [144, 144, 144],
        mass: 12.0110,
    },
    Element {
        symbol: "N",
        number: 7,
        covalent_radius: 0.71,
        vdw_radius: 1.66,
        color: [48, 80, 248],
        mass: 14.0070,
    },
    Element {
        symbol: "O",
        number: 8,
        covalent_radius: 0.66,
        vdw_radius: 1.50,
        color: [255, 13, 13],
        mass: 15.9990,
    },
    Element {
        symbol: "F",
        number: 9,
        covalent_radius: 0.57,
        vdw_radius: 1.46,
        color: [144, 224, 80],
        mass: 18.9984,
    },
    Element {
        symbol: "Ne",
        number: 10,
        covalent_radius: 0.58,
        vdw_radius: 1.58,
        color: [179, 227, 245],
        mass: 20.1797,
    },
    Element {
        symbol: "Na",
        number: 11,
        covalent_radius: 1.66,
        vdw_radius: 2.50,
        color: [171, 92, 242],
        mass: 22.9898,
    },
    Element {
        symbol: "Mg",
        number: 12,
        covalent_radius: 1.41,
        vdw_radius: 2.51,
        color: [138, 255, 0],
        mass: 24.3050,
    },
    Element {
        symbol: "Al",
        number: 13,
        covalent_radius: 1.21,
        vdw_radius: 2.25,
        color: [191, 166, 166],
        mass: 26.9815,
    },
    Element {
        symbol: "Si",
        number: 14,
        covalent_radius: 1.11,
        vdw_radius: 2.19,
        color: [240, 200, 160],
        mass: 28.0850,
    },
    Element {
        symbol: "P",
        number: 15,
        covalent_radius: 1.07,
        vdw_radius: 1.90,
        color: [255, 128, 0],
        mass: 30.9738,
    },
    Element {
        symbol: "S",
        number: 16,
        covalent_radius: 1.05,
        vdw_radius: 1.89,
        color: [255, 255, 48],
        mass: 32.0600,
    },
    Element {
        symbol: "Cl",
        number: 17,
        covalent_radius: 1.02,
        vdw_radius: 1.82,
        color: [31, 240, 31],
        mass: 35.4500,
    },
    Element {
        symbol: "Ar",
        number: 18,
        covalent_radius: 1.06,
        vdw_radius: 1.83,
        color: [128, 209, 227],
        mass: 39.9480,
    },
    Element {
        symbol: "K",
        number: 19,
        covalent_radius: 2.03,
        vdw_radius: 2.73,
        color: [143, 64, 212],
        mass: 39.0983,
    },
    Element {
        symbol: "Ca",
        number: 20,
        covalent_radius: 1.76,
        vdw_radius: 2.62,
        color: [61, 255, 0],
        mass: 40.0780,
    },
    Element {
        symbol: "Sc",
        number: 21,
        covalent_radius: 1.70,
        vdw_radius: 2.58,
        color: [230, 230, 230],
        mass: 44.9559,
    },
    Element {
        symbol: "Ti",
        number: 22,
        covalent_radius: 1.60,
        vdw_radius: 2.46,
        color: [191, 194, 199],
        mass: 47.8670,
    },
    Element {
        symbol: "V",
        number: 23,
        covalent_radius: 1.53,
        vdw_radius: 2.42,
        color: [166, 166, 171],
        mass: 50.9415,
    },
    Element {
        symbol: "Cr",
        number: 24,
        covalent_radius: 1.39,
        vdw_radius: 2.45,
        color: [138, 153, 199],
        mass: 51.9961,
    },
    Element {
        symbol: "Mn",
        number: 25,
        covalent_radius: 1.39,
        vdw_radius: 2.45,
        color: [156, 122, 199],
        mass: 54.9380,
    },
    Element {
        symbol: "Fe",
        number: 26,
        covalent_radius: 1.32,
        vdw_radius: 2.44,
        color: [224, 102, 51],
        mass: 55.8450,
    },
    Element {
        symbol: "Co",
        number: 27,
        covalent_radius: 1.26,
        vdw_radius: 2.40,
        color: [240, 144, 160],
        mass: 58.9332,
    },
    Element {
        symbol: "Ni",
        number: 28,
        covalent_radius: 1.24,
        vdw_radius: 2.40,
        color: [80, 208, 80],
        mass: 58.6934,
    },
    Element {
        symbol: "Cu",
        number: 29,
        covalent_radius: 1.32,
        vdw_radius: 2.38,
        color: [200, 128, 51],
        mass: 63.5460,
    },
    Element {
        symbol: "Zn",
        number: 30,
        covalent_radius: 1.22,
        vdw_radius: 2.39,
        color: [125, 128, 176],
        mass: 65.3800,
    },
    Element {
        symbol: "Ga",
        number: 31,
        covalent_radius: 1.22,
        vdw_radius: 2.32,
        color: [194, 143, 143],
        mass: 69.7230,
    },
    Element {
        symbol: "Ge",
        number: 32,
        covalent_radius: 1.20,
        vdw_radius: 2.29,
        color: [102, 143, 143],
        mass: 72.6300,
    },
    Element {
        symbol: "As",
        number: 33,
        covalent_radius: 1.19,
        vdw_radius: 1.88,
        color: [189, 128, 227],
        mass: 74.9216,
    },
    Element {
        symbol: "Se",
        number: 34,
        covalent_radius: 1.20,
        vdw_radius: 1.82,
        color: [255, 161, 0],
        mass: 78.9710,
    },
    Element {
        symbol: "Br",
        number: 35,
        covalent_radius: 1.20,
        vdw_radius: 1.86,
        color: [166, 41, 41],
        mass: 79.9040,
    },
    Element {
        symbol: "Kr",
        number: 36,
        covalent_radius: 1.16,
        vdw_radius: 2.25,
        color: [92, 184, 209],
        mass: 83.7980,
    },
    Element {
        symbol: "Rb",
        number: 37,
        covalent_radius: 2.20,
        vdw_radius: 3.21,
        color: [112, 46, 176],
        mass: 85.4678,
    },
    Element {
        symbol: "Sr",
        number: 38,
        covalent_radius: 1.95,
        vdw_radius: 2.84,
        color: [0, 255, 0],
        mass: 87.6200,
    },
    Element {
        symbol: "Y",
        number: 39,
        covalent_radius: 1.90,
        vdw_radius: 2.75,
        color: [148, 255, 255],
        mass: 88.9058,
    },
    Element {
        symbol: "Zr",
        number: 40,
        covalent_radius: 1.75,
        vdw_radius: 2.52,
        color: [148, 224, 224],
        mass: 91.2240,
    },
    Element {
        symbol: "Nb",
        number: 41,
        covalent_radius: 1.64,
        vdw_radius: 2.56,
        color: [115, 194, 201],
        mass: 92.9064,
    },
    Element {
        symbol: "Mo",
        number: 42,
        covalent_radius: 1.54,
        vdw_radius: 2.45,
        color: [84, 181, 181],
        mass: 95.9500,
    },
    Element {
        symbol: "Tc",
        number: 43,
        covalent_radius: 1.47,
        vdw_radius: 2.44,
        color: [59, 158, 158],
        mass: 97.9072,
    },
    Element {
        symbol: "Ru",
        number: 44,
        covalent_radius: 1.46,
        vdw_radius: 2.46,
        color: [36, 143, 143],
        mass: 101.0700,
    },
    Element {
        symbol: "Rh",
        number: 45,
        covalent_radius: 1.42,
        vdw_radius: 2.44,
        color: [10, 125, 140],
        mass: 102.9055,
    },
    Element {
        symbol: "Pd",
        number: 46,
        covalent_radius: 1.39,
        vdw_radius: 2.15,
        color: [0, 105, 133],
        mass: 106.4200,
    },
    Element {
        symbol: "Ag",
        number: 47,
        covalent_radius: 1.45,
        vdw_radius: 2.53,
        color: [192, 192, 192],
        mass: 107.8682,
    },
    Element {
        symbol: "Cd",
        number: 48,
        covalent_radius: 1.44,
        vdw_radius: 2.49,
        color: [255, 217, 143],
        mass: 112.4140,
    },
    Element {
        symbol: "In",
        number: 49,
        covalent_radius: 1.42,
        vdw_radius: 2.43,
        color: [166, 117, 115],
        mass: 114.8180,
    },
    Element {
        symbol: "Sn",
        number: 50,
        covalent_radius: 1.39,
        vdw_radius: 2.42,
        color: [102, 128, 128],
        mass: 118.7100,
    },
    Element {
        symbol: "Sb",
        number: 51,
        covalent_radius: 1.39,
        vdw_radius: 2.47,
        color: [158, 99, 181],
        mass: 121.7600,
    },
    Element {
        symbol: "Te",
        number: 52,
        covalent_radius: 1.38,
        vdw_radius: 1.99,
        color: [212, 122, 0],
        mass: 127.6000,
    },
    Element {
        symbol: "I",
        number: 53,
        covalent_radius: 1.39,
        vdw_radius: 2.04,
        color: [148, 0, 148],
        mass: 126.9045,
    },
    Element {
        symbol: "Xe",
        number: 54,
        covalent_radius: 1.40,
        vdw_radius: 2.06,
        color: [66, 158, 176],
        mass: 131.2930,
    },
    Element {
        symbol: "Cs",
        number: 55,
        covalent_radius: 2.44,
        vdw_radius: 3.48,
        color: [87, 23, 143],
        mass: 132.9055,
    },
    Element {
        symbol: "Ba",
        number: 56,
        covalent_radius: 2.15,
        vdw_radius: 3.03,
        color: [0, 201, 0],
        mass: 137.3270,
    },
    Element {
        symbol: "La",
        number: 57,
        covalent_radius: 2.07,
        vdw_radius: 2.98,
        color: [112, 212, 255],
        mass: 138.9055,
    },
    Element {
        symbol: "Ce",
        number: 58,
        covalent_radius: 2.04,
        vdw_radius: 2.88,
        color: [255, 255, 199],
        mass: 140.1160,
    },
    Element {
        symbol: "Pr",
        number: 59,
        covalent_radius: 2.03,
        vdw_radius: 2.92,
        color: [217, 255, 199],
        mass: 140.9077,
    },
    Element {
        symbol: "Nd",
        number: 60,
        covalent_radius: 2.01,
        vdw_radius: 2.95,
        color: [199, 255, 199],
        mass: 144.2420,
    },
    Element {
        symbol: "Pm",
        number: 61,
        covalent_radius: 1.99,
        vdw_radius: 2.00,
        color: [163, 255, 199],
        mass: 144.9128,
    },
    Element {
        symbol: "Sm",
        number: 62,
        covalent_radius: 1.98,
        vdw_radius: 2.90,
        color: [143, 255, 199],
        mass: 150.3600,
    },
    Element {
        symbol: "Eu",
        number: 63,
        covalent_radius: 1.98,
        vdw_radius: 2.87,
        color: [97, 255, 199],
        mass: 151.9640,
    },
    Element {
        symbol: "Gd",
        number: 64,
        covalent_radius: 1.96,
        vdw_radius: 2.83,
        color: [69, 255, 199],
        mass: 157.2500,
    },
    Element {
        symbol: "Tb",
        number: 65,
        covalent_radius: 1.94,
        vdw_radius: 2.79,
        color: [48, 255, 199],
        mass: 158.9254,
    },
    Element {
        symbol: "Dy",
        number: 66,
        covalent_radius: 1.92,
        vdw_radius: 2.87,
        color: [31, 255, 199],
        mass: 162.5000,
    },
    Element {
        symbol: "Ho",
        number: 67,
        covalent_radius: 1.92,
        vdw_radius: 2.81,
        color: [0, 255, 156],
        mass: 164.9303,
    },
    Element {
        symbol: "Er",
        number: 68,
        covalent_radius: 1.89,
        vdw_radius: 2.83,
        color: [0, 230, 117],
        mass: 167.2590,
    },
    Element {
        symbol: "Tm",
        number: 69,
        covalent_radius: 1.90,
        vdw_radius: 2.79,
        color: [0, 212, 82],
        mass: 168.9342,
    },
    Element {
        symbol: "Yb",
        number: 70,
        covalent_radius: 1.87,
        vdw_radius: 2.80,
        color: [0, 191, 56],
        mass: 173.0540,
    },
    Element {
        symbol: "Lu",
        number: 71,
        covalent_radius: 1.87,
        vdw_radius: 2.74,
        color: [0, 171, 36],
        mass: 174.9668,
    },
    Element {
        symbol: "Hf",
        number: 72,
        covalent_radius: 1.75,
        vdw_radius: 2.63,
        color: [77, 194, 255],
        mass: 178.4900,
    },
    Element {
        symbol: "Ta",
        number: 73,
        covalent_radius: 1.70,
        vdw_radius: 2.53,
        color: [77, 166, 255],
        mass: 180.9479,
    },
    Element {
        symbol: "W",
        number: 74,
        covalent_radius: 1.62,
        vdw_radius: 2.57,
        color: [33, 148, 214],
        mass: 183.8400,
    },
    Element {
        symbol: "Re",
        number: 75,
        covalent_radius: 1.51,
        vdw_radius: 2.49,
        color: [38, 125, 171],
        mass: 186.2070,
    },
    Element {
        symbol: "Os",
        number: 76,
        covalent_radius: 1.44,
        vdw_radius: 2.48,
        color: [38, 102, 150],
        mass: 190.2300,
    },
    Element {
        symbol: "Ir",
        number: 77,
        covalent_radius: 1.41,
        vdw_radius: 2.41,
        color: [23, 84, 135],
        mass: 192.2170,
    },
    Element {
        symbol: "Pt",
        number: 78,
        covalent_radius: 1.36,
        vdw_radius: 2.29,
        color: [208, 208, 224],
        mass: 195.0840,
    },
    Element {
        symbol: "Au",
        number: 79,
        covalent_radius: 1.36,
        vdw_radius: 2.32,
        color: [255, 209, 35],
        mass: 196.9666,
    },
    Element {
        symbol: "Hg",
        number: 80,
        covalent_radius: 1.32,
        vdw_radius: 2.45,
        color: [184, 184, 208],
        mass: 200.5920,
    },
    Element {
        symbol: "Tl",
        number: 81,
        covalent_radius: 1.45,
        vdw_radius: 2.47,
        color: [166, 84, 77],
        mass: 204.3800,
    },
    Element {
        symbol: "Pb",
        number: 82,
        covalent_radius: 1.46,
        vdw_radius: 2.60,
        color: [87, 89, 97],
        mass: 207.2000,
    },
    Element {
        symbol: "Bi",
        number: 83,
        covalent_radius: 1.48,
        vdw_radius: 2.54,
        color: [158, 79, 181],
        mass: 208.9804,
    },
    Element {
        symbol: "Po",
        number: 84,
        covalent_radius: 1.40,
        vdw_radius: 2.00,
        color: [171, 92, 0],
        mass: 208.9824,
    },
    Element {
        symbol: "At",
        number: 85,
        covalent_radius: 1.50,
        vdw_radius: 2.00,
        color: [117, 79, 69],
        mass: 209.9872,
    },
    Element {
        symbol: "Rn",
        number: 86,
        covalent_radius: 1.50,
        vdw_radius: 2.00,
        color: [66, 130, 150],
        mass: 222.0176,
    },
    Element {
        symbol: "Fr",
        number: 87,
        covalent_radius: 2.60,
        vdw_radius: 2.00,
        color: [66, 0, 102],
        mass: 223.0197,
    },
    Element {
        symbol: "Ra",
        number: 88,
        covalent_radius: 2.21,
        vdw_radius: 2.00,
        color: [0, 125, 0],
        mass: 226.0254,
    },
    Element {
        symbol: "Ac",
        number: 89,
        covalent_radius: 2.15,
        vdw_radius: 2.80,
        color: [112, 171, 250],
        mass: 227.0277,
    },
    Element {
        symbol: "Th",
        number: 90,
        covalent_radius: 2.06,
        vdw_radius: 2.93,
        color: [0, 186, 255],
        mass: 232.0377,
    },
    Element {
        symbol: "Pa",
        number: 91,
        covalent_radius: 2.00,
        vdw_radius: 2.88,
        color: [0, 161, 255],
        mass: 231.0359,
    },
    Element {
        symbol: "U",
        number: 92,
        covalent_radius: 1.96,
        vdw_radius: 2.71,
        color: [0, 143, 255],
        mass: 238.0289,
    },
    Element {
        symbol: "Np",
        number: 93,
        covalent_radius: 1.90,
        vdw_radius: 2.82,
        color: [0, 128, 255],
        mass: 237.0482,
    },
    Element {
        symbol: "Pu",
        number: 94,
        covalent_radius: 1.87,
        vdw_radius: 2.81,
        color: [0, 107, 255],
        mass: 244.0642,
    },
    Element {
        symbol: "Am",
        number: 95,
        covalent_radius: 1.80,
        vdw_radius: 2.83,
        color: [84, 92, 242],
        mass: 243.0614,
    },
    Element {
        symbol: "Cm",
        number: 96,
        covalent_radius: 1.69,
        vdw_radius: 3.05,
        color: [120, 92, 227],
        mass: 247.0703,
    },
    Element {
        symbol: "Bk",
        number: 97,
        covalent_radius: 2.00,
        vdw_radius: 3.40,
        color: [138, 79, 227],
        mass: 247.0703,
    },
    Element {
        symbol: "Cf",
        number: 98,
        covalent_radius: 2.00,
        vdw_radius: 3.05,
        color: [161, 54, 212],
        mass: 251.0796,
    },
    Element {
        symbol: "Es",
        number: 99,
        covalent_radius: 2.00,
        vdw_radius: 2.70,
        color: [179, 31, 212],
        mass: 252.0830,
    },
    Element {
        symbol: "Fm",
        number: 100,
        covalent_radius: 2.00,
        vdw_radius: 2.00,
        color: [179, 31, 186],
        mass: 257.0951,
    },
    Element {
        symbol: "Md",
        number: 101,
        covalent_radius: 2.00,
        vdw_radius: 2.00,
        color: [179, 13, 166],
        mass: 258.0984,
    },
    Element {
        symbol: "No",
        number: 102,
        covalent_radius: 2.00,
        vdw_radius: 2.00,
        color: [189, 13, 135],
        mass: 259.1010,
    },
    Element {
        symbol: "Lr",
        number: 103,
        covalent_radius: 2.00,
        vdw_radius: 2.00,
        color: [199, 0, 102],
        mass: 262.1100,
    },
];

/// The element with atomic number `z`; anything above [`MAX_Z`] maps to unknown (Z = 0).
pub fn element(z: u8) -> &'static Element {
    TABLE.get(z as usize).unwrap_or(&TABLE[0])
}

/// All table entries, index = Z (entry 0 is unknown).
pub fn all() -> &'static [Element] {
    &TABLE
}

/// Atomic number of a chemical symbol, case-insensitive (`"al"`, `"AL"`, `"Al"`), ignoring
/// surrounding whitespace. `None` if it is not an element symbol (`"X"` is not accepted).
pub fn by_symbol(s: &str) -> Option<u8> {
    let s = s.trim();
    let b = s.as_bytes();
    if b.is_empty() || b.len() > 2 || !b.iter().all(|c| c.is_ascii_alphabetic()) {
        return None;
    }
    TABLE[1..]
        .iter()
        .find(|e| e.symbol.eq_ignore_ascii_case(s))
        .map(|e| e.number)
}

/// Element whose standard atomic weight is nearest to `mass` (u), if within 0.5 u
/// (LAMMPS `Masses` section). Returns `None` for masses that match nothing well.
pub fn by_mass(mass: f32) -> Option<u8> {
    if !mass.is_finite() || mass <= 0.0 {
        return None;
    }
    let (best, d) = TABLE[1..]
        .iter()
        .map(|e| (e.number, (e.mass - mass).abs()))
        .fold((0u8, f32::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
    (d <= 0.5).then_some(best)
}

/// Guess the element from a PDB/GRO atom name such as `"CA"`, `"HT1"`, `"OW"`, `"NA+"`:
/// strips digits and charges, then tries a two-letter symbol only for names that are not
/// common biomolecular atom names (so `CA` is carbon alpha, `HG1` hydrogen), else the first
/// letter. Returns `None` if nothing matches.
pub fn guess_from_name(name: &str) -> Option<u8> {
    let letters: String = name
        .trim()
        .chars()
        .skip_while(|c| c.is_ascii_digit())
        .take_while(|c| c.is_ascii_alphabetic())
        .collect();
    if letters.is_empty() {
        return None;
    }
    let up = letters.to_ascii_uppercase();
    // Ions and two-letter names that are really two-letter elements.
    const TWO: [&str; 12] = [
        "NA", "CL", "MG", "ZN", "FE", "CA", "K", "LI", "BR", "MN", "CU", "AL",
    ];
    // An all-caps atom name like "CA" in a protein is C-alpha; only treat as ion if it is the
    // whole name (residue-less ion names are usually exactly the symbol, e.g. "NA", "CL").
    let rest_is_empty = up.len() == 2 && name.trim().len() <= 3;
    if up.len() >= 2 && rest_is_empty && TWO.contains(&&up[..2]) && up != "CA" {
        return by_symbol(&up[..2]);
    }
    by_symbol(&up[..1])
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn basics() {
        assert_eq!(by_symbol("Al"), Some(13));
        assert_eq!(by_symbol("al"), Some(13));
        assert_eq!(by_symbol("Xx"), None);
        assert_eq!(element(6).covalent_radius, 0.76);
        assert_eq!(element(200).number, 0);
        assert_eq!(by_mass(12.011), Some(6));
        assert_eq!(by_mass(15.9994), Some(8));
        assert_eq!(guess_from_name("CA"), Some(6));
        assert_eq!(guess_from_name("HT1"), Some(1));
        assert_eq!(guess_from_name("NA+"), Some(11));
        assert_eq!(guess_from_name("OW"), Some(8));
        assert_eq!(guess_from_name("CL-"), Some(17));
        for (z, e) in all().iter().enumerate() {
            assert_eq!(e.number as usize, z);
        }
    }
}
