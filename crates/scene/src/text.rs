//! The text forms of values users type in flags and scripts, parsed with an error that says
//! what was expected: sizes `WIDTHxHEIGHT`, points and directions `x,y,z` (Å), ranges `LO:HI`,
//! colours `r,g,b`, positive numbers. (The `Err` is a message, as clap's value parsers take.)

/// Three finite numbers `x,y,z`.
pub fn vec3(s: &str) -> Option<[f32; 3]> {
    let v: Vec<Option<f32>> = s.split(',').map(|c| c.trim().parse().ok()).collect();
    match v.as_slice() {
        [Some(x), Some(y), Some(z)] if [x, y, z].iter().all(|a| a.is_finite()) => {
            Some([*x, *y, *z])
        }
        _ => None,
    }
}

/// Parses a direction `x,y,z` (not zero).
pub fn parse_dir(s: &str) -> Result<[f32; 3], String> {
    vec3(s)
        .filter(|v| v.iter().any(|c| *c != 0.0))
        .ok_or_else(|| format!("{s:?}: expected a non-zero direction x,y,z"))
}

/// Parses a positive finite number.
pub fn positive(s: &str) -> Result<f32, String> {
    s.trim()
        .parse::<f32>()
        .ok()
        .filter(|v| *v > 0.0 && v.is_finite())
        .ok_or_else(|| format!("{s:?}: expected a positive number"))
}

/// Parses a finite number ≥ 0.
pub fn non_negative(s: &str) -> Result<f32, String> {
    s.trim()
        .parse::<f32>()
        .ok()
        .filter(|v| *v >= 0.0 && v.is_finite())
        .ok_or_else(|| format!("{s:?}: expected a number ≥ 0"))
}

/// Parses a point `x,y,z` (Å).
pub fn parse_point(s: &str) -> Result<[f32; 3], String> {
    vec3(s).ok_or_else(|| format!("{s:?}: expected a point x,y,z in Å (three finite numbers)"))
}

/// Parses `WIDTHxHEIGHT`.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("{s:?}: expected WIDTHxHEIGHT, e.g. 1024x1024"))?;
    let p = |v: &str| v.trim().parse::<u32>().ok().filter(|&n| n > 0);
    match (p(w), p(h)) {
        (Some(w), Some(h)) => Ok((w, h)),
        _ => Err(format!("{s:?}: width and height must be positive integers")),
    }
}

/// Parses a colour `r,g,b`, each 0-255.
pub fn parse_rgb(s: &str) -> Result<[u8; 3], String> {
    let v: Vec<Option<u8>> = s.split(',').map(|c| c.trim().parse().ok()).collect();
    match v.as_slice() {
        [Some(r), Some(g), Some(b)] => Ok([*r, *g, *b]),
        _ => Err(format!("{s:?}: expected r,g,b with each 0-255")),
    }
}

/// `LO:HI`, two finite numbers with LO < HI.
pub fn parse_range(s: &str) -> Result<(f32, f32), String> {
    let bad = || format!("expected LO:HI, two finite numbers with LO < HI (e.g. -1:1), got {s:?}");
    let (lo, hi) = s.split_once(':').ok_or_else(bad)?;
    let (lo, hi): (f32, f32) = (
        lo.trim().parse().map_err(|_| bad())?,
        hi.trim().parse().map_err(|_| bad())?,
    );
    if lo.is_finite() && hi.is_finite() && lo < hi {
        Ok((lo, hi))
    } else {
        Err(bad())
    }
}

/// Parses `N` (N×N) or `WxH`.
pub fn parse_side(s: &str) -> Result<(u32, u32), String> {
    if s.contains(['x', 'X']) {
        return parse_size(s);
    }
    match s.trim().parse::<u32>() {
        Ok(n) if n > 0 => Ok((n, n)),
        _ => Err(format!(
            "{s:?}: expected a positive edge length N or WIDTHxHEIGHT"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_parse_and_bad_ones_say_what_was_expected() {
        assert_eq!(parse_size("640x480"), Ok((640, 480)));
        assert_eq!(parse_side("512"), Ok((512, 512)));
        assert_eq!(parse_side("64X32"), Ok((64, 32)));
        assert_eq!(parse_range("-1:2.5"), Ok((-1.0, 2.5)));
        assert_eq!(parse_point("1, -2,3"), Ok([1.0, -2.0, 3.0]));
        assert_eq!(parse_rgb("255,0,10"), Ok([255, 0, 10]));
        for bad in ["0x5", "5", "axb", "-1x4"] {
            assert!(parse_size(bad).unwrap_err().contains(bad), "{bad}");
        }
        assert!(parse_range("2:1").unwrap_err().contains("LO < HI"));
        assert!(parse_range("nan:1").is_err() && parse_point("1,inf,2").is_err());
        assert!(parse_dir("0,0,0").unwrap_err().contains("non-zero"));
        assert!(positive("0").is_err() && non_negative("0") == Ok(0.0));
        assert!(parse_rgb("256,0,0").is_err());
    }
}
