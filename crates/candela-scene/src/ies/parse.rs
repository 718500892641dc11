//! The LM-63 grammar: version line, keyword (or free-text) lines up to `TILT=`, then a
//! stream of numbers: tilt data, the 10 header numbers, the 3 ballast numbers, the
//! vertical and horizontal angles and the candela values.

use std::path::Path;

use candela_core::desc::Span;
use candela_core::photometry::HorizontalSymmetry;

use super::{IesFile, IesUnits, IesVersion, Tilt, TiltTable};
use crate::LoadError;

/// Parses the bytes of an IES file named `file` (used in errors, and to find a
/// `TILT=<file>` next to it). Never panics on malformed input.
pub fn parse_ies(bytes: &[u8], file: &str) -> Result<IesFile, LoadError> {
    let text = decode(bytes);
    let lines: Vec<&str> = text.split('\n').map(|l| l.trim_end_matches('\r')).collect();
    let err = |line: usize, col: usize, message: String| LoadError {
        span: Span::new(file, line as u32, col as u32),
        message,
    };

    // Version line.
    let first = lines[0].trim();
    let upper = first.to_ascii_uppercase();
    let (version, header_start) = match upper.as_str() {
        "IESNA91" => (IesVersion::Lm63_1991, 1),
        "IESNA:LM-63-1995" => (IesVersion::Lm63_1995, 1),
        "IESNA:LM-63-2002" => (IesVersion::Lm63_2002, 1),
        "IES:LM-63-2019" => (IesVersion::Lm63_2019, 1),
        _ if upper.starts_with("IESNA") || upper.starts_with("IES:") => {
            return Err(err(1, 1, format!("unknown LM-63 version line \"{first}\"")))
        }
        _ => (IesVersion::Lm63_1986, 0),
    };

    // Keyword or free-text lines up to TILT=.
    let mut keywords: Vec<(String, String)> = Vec::new();
    let mut free_text = Vec::new();
    let mut tilt_line = None;
    for (i, raw) in lines.iter().enumerate().skip(header_start) {
        let line = raw.trim();
        // `get`: a Latin-1 header line may have a multi-byte character before byte 5.
        if line
            .get(..5)
            .is_some_and(|t| t.eq_ignore_ascii_case("TILT="))
        {
            tilt_line = Some((i, line[5..].trim().to_string()));
            break;
        }
        match line.strip_prefix('[').and_then(|l| l.split_once(']')) {
            Some((key, value)) if key.eq_ignore_ascii_case("MORE") && !keywords.is_empty() => {
                let last = keywords.last_mut().expect("not empty");
                last.1.push('\n');
                last.1.push_str(value.trim());
            }
            Some((key, value)) => keywords.push((key.trim().to_string(), value.trim().into())),
            None => free_text.push(raw.trim_end().to_string()),
        }
    }
    let Some((tilt_index, tilt_value)) = tilt_line else {
        return Err(err(
            lines.len(),
            0,
            "no TILT= line: the header must end with TILT=NONE, TILT=INCLUDE or TILT=<file>".into(),
        ));
    };

    let mut tokens = Tokens::new(file, &lines, tilt_index + 1);
    let tilt = match tilt_value.to_ascii_uppercase().as_str() {
        "NONE" => Tilt::None,
        "INCLUDE" => Tilt::Include(read_tilt(&mut tokens)?),
        _ => {
            let dir = Path::new(file).parent().unwrap_or(Path::new(""));
            let path = dir.join(&tilt_value);
            let bytes = std::fs::read(&path).map_err(|e| {
                err(
                    tilt_index + 1,
                    1,
                    format!(
                        "TILT file \"{tilt_value}\" cannot be read ({}: {e})",
                        path.display()
                    ),
                )
            })?;
            let tilt_text = decode(&bytes);
            let tilt_lines: Vec<&str> = tilt_text.split('\n').collect();
            let name = path.display().to_string();
            let table = read_tilt(&mut Tokens::new(&name, &tilt_lines, 0))?;
            Tilt::File(tilt_value.clone(), table)
        }
    };

    // The 10 header numbers and the 3 ballast numbers.
    let lamp_count = tokens.integer("the number of lamps", 1, u32::MAX)?;
    let lumens_per_lamp = tokens.number("lumens per lamp")?.0;
    let (multiplier, at) = tokens.number("the candela multiplier")?;
    if multiplier <= 0.0 {
        return Err(tokens.error_at(at, format!("candela multiplier {multiplier} must be > 0")));
    }
    let n_vertical = tokens.integer("the number of vertical angles", 2, 100_000)? as usize;
    let n_horizontal = tokens.integer("the number of horizontal angles", 1, 100_000)? as usize;
    let counts_line = tokens.last_line();
    let (photometric_type, at) = tokens.integer_at("the photometric type", 1, 3)?;
    if photometric_type != 1 {
        let name = if photometric_type == 2 { "B" } else { "A" };
        return Err(tokens.error_at(
            at,
            format!("photometric type {name} is not supported (only type C, 1, is)"),
        ));
    }
    let units = match tokens.integer("the units type (1 = feet, 2 = meters)", 1, 2)? {
        1 => IesUnits::Feet,
        _ => IesUnits::Meters,
    };
    let mut dimensions = [0.0; 3];
    for (d, what) in dimensions.iter_mut().zip(["width", "length", "height"]) {
        *d = tokens.number(what)?.0;
    }
    let (ballast_factor, at) = tokens.number("the ballast factor")?;
    if ballast_factor <= 0.0 {
        return Err(tokens.error_at(at, format!("ballast factor {ballast_factor} must be > 0")));
    }
    let (ballast_lamp_factor, at) = tokens.number("the ballast-lamp photometric factor")?;
    let old = matches!(
        version,
        IesVersion::Lm63_1986 | IesVersion::Lm63_1991 | IesVersion::Lm63_1995
    );
    if old && ballast_lamp_factor <= 0.0 {
        return Err(tokens.error_at(
            at,
            format!("ballast-lamp photometric factor {ballast_lamp_factor} must be > 0"),
        ));
    }
    let input_watts = tokens.number("input watts")?.0;

    // The counts must match the data before the data is read value by value.
    let expected = n_vertical + n_horizontal + n_vertical * n_horizontal;
    let found = tokens.remaining();
    let counts = format!(
        "{n_vertical} vertical × {n_horizontal} horizontal angles (line {counts_line}) need \
         {expected} numbers after the header"
    );
    if found < expected {
        let (line, col) = tokens.end();
        return Err(err(
            line,
            col,
            format!("truncated data: {counts}, found {found}"),
        ));
    }
    if found > expected {
        return Err(err(
            counts_line,
            0,
            format!("counts do not match the data: {counts}, found {found}"),
        ));
    }

    let vertical_angles = tokens.angles("vertical", n_vertical, 180.0)?;
    let first_horizontal = tokens.peek_pos();
    let horizontal_angles = tokens.angles("horizontal", n_horizontal, 360.0)?;
    HorizontalSymmetry::classify(&horizontal_angles)
        .map_err(|e| tokens.error_at(first_horizontal, e.0))?;
    let tilt_factor = match &tilt {
        Tilt::None => 1.0,
        Tilt::Include(t) | Tilt::File(_, t) => t.factor(0.0),
    };
    let scale =
        multiplier * ballast_factor * if old { ballast_lamp_factor } else { 1.0 } * tilt_factor;
    let mut candela = Vec::with_capacity(n_vertical * n_horizontal);
    for _ in 0..n_vertical * n_horizontal {
        let (c, at) = tokens.number("a candela value")?;
        if c < 0.0 {
            return Err(tokens.error_at(at, format!("negative candela value {c}")));
        }
        candela.push(c * scale);
    }

    Ok(IesFile {
        version,
        keywords,
        text: free_text,
        tilt,
        lamp_count,
        lumens_per_lamp,
        multiplier,
        photometric_type,
        units,
        dimensions,
        ballast_factor,
        ballast_lamp_factor,
        input_watts,
        vertical_angles,
        horizontal_angles,
        candela,
        span: Span::new(file, 0, 0),
    })
}

/// Text from bytes: UTF-8 where valid (a byte-order mark dropped), else Latin-1 (every
/// byte one character). The DOS end-of-file byte ^Z becomes a space, and lines end with
/// `\n` whether the file ends them with LF, CR LF or a lone CR (classic Mac OS).
fn decode(bytes: &[u8]) -> String {
    let text = match std::str::from_utf8(bytes) {
        Ok(s) => s.strip_prefix('\u{feff}').unwrap_or(s).to_string(),
        Err(_) => bytes.iter().map(|&b| b as char).collect(),
    };
    text.replace('\u{1a}', " ")
        .replace("\r\n", "\n")
        .replace('\r', "\n")
}

/// Tilt data: lamp geometry, pair count, angles, factors.
fn read_tilt(tokens: &mut Tokens) -> Result<TiltTable, LoadError> {
    let lamp_geometry = tokens.integer("the lamp-to-luminaire geometry (1, 2 or 3)", 1, 3)?;
    let n = tokens.integer("the number of tilt angles", 1, 100_000)? as usize;
    let angles = tokens.angles("tilt", n, 180.0)?;
    let mut factors = Vec::with_capacity(n);
    for _ in 0..n {
        let (f, at) = tokens.number("a tilt multiplying factor")?;
        if f < 0.0 {
            return Err(tokens.error_at(at, format!("negative tilt factor {f}")));
        }
        factors.push(f);
    }
    Ok(TiltTable {
        lamp_geometry,
        angles,
        factors,
    })
}

/// One whitespace- or comma-separated word after the header, with its 1-based position.
struct Token<'a> {
    text: &'a str,
    line: usize,
    col: usize,
}

/// The number stream after `TILT=`, up to an `END` word or the end of the file.
struct Tokens<'a> {
    file: &'a str,
    tokens: Vec<Token<'a>>,
    next: usize,
    /// Last line of the stream, for errors about missing data.
    end_line: usize,
    /// Column just after the stream's last word on `end_line`.
    end_col: usize,
}

impl<'a> Tokens<'a> {
    fn new(file: &'a str, lines: &[&'a str], start: usize) -> Tokens<'a> {
        let mut tokens = Vec::new();
        let mut end_line = start.max(1);
        let mut end_col = 1;
        'lines: for (i, line) in lines.iter().enumerate().skip(start) {
            let mut offset = 0;
            for word in line.split(|c: char| c.is_whitespace() || c == ',') {
                let col = offset + 1;
                offset += word.len() + 1;
                if word.is_empty() {
                    continue;
                }
                if word.eq_ignore_ascii_case("END") {
                    break 'lines;
                }
                tokens.push(Token {
                    text: word,
                    line: i + 1,
                    col,
                });
                end_line = i + 1;
                end_col = col + word.len();
            }
        }
        Tokens {
            file,
            tokens,
            next: 0,
            end_line,
            end_col,
        }
    }

    fn error_at(&self, index: usize, message: String) -> LoadError {
        let t = &self.tokens[index];
        LoadError {
            span: Span::new(self.file, t.line as u32, t.col as u32),
            message,
        }
    }

    fn remaining(&self) -> usize {
        self.tokens.len() - self.next
    }

    /// Where data is missing: just after the last word.
    fn end(&self) -> (usize, usize) {
        (self.end_line, self.end_col)
    }

    /// Line of the token read last.
    fn last_line(&self) -> usize {
        self.next
            .checked_sub(1)
            .map_or(self.end_line, |i| self.tokens[i].line)
    }

    fn peek_pos(&self) -> usize {
        self.next
    }

    /// The next finite number and its token index.
    fn number(&mut self, what: &str) -> Result<(f64, usize), LoadError> {
        let Some(t) = self.tokens.get(self.next) else {
            return Err(LoadError {
                span: Span::new(self.file, self.end_line as u32, self.end_col as u32),
                message: format!("truncated data: expected {what}, found the end of the file"),
            });
        };
        match t.text.parse::<f64>() {
            Ok(v) if v.is_finite() => {
                self.next += 1;
                Ok((v, self.next - 1))
            }
            _ => Err(self.error_at(
                self.next,
                format!("expected {what} (a number), found \"{}\"", t.text),
            )),
        }
    }

    /// The next number, which must be a whole number in `lo..=hi`, and its token index.
    fn integer_at(&mut self, what: &str, lo: u32, hi: u32) -> Result<(u32, usize), LoadError> {
        let (v, at) = self.number(what)?;
        if v.fract() != 0.0 || v < lo as f64 || v > hi as f64 {
            return Err(self.error_at(
                at,
                format!("{what} must be a whole number from {lo} to {hi}, found {v}"),
            ));
        }
        Ok((v as u32, at))
    }

    fn integer(&mut self, what: &str, lo: u32, hi: u32) -> Result<u32, LoadError> {
        Ok(self.integer_at(what, lo, hi)?.0)
    }

    /// `n` strictly increasing angles within 0..=`max` degrees.
    fn angles(&mut self, what: &str, n: usize, max: f64) -> Result<Vec<f64>, LoadError> {
        let mut angles: Vec<f64> = Vec::with_capacity(n);
        for _ in 0..n {
            let (a, at) = self.number(&format!("a {what} angle"))?;
            if !(0.0..=max).contains(&a) {
                return Err(self.error_at(at, format!("{what} angle {a} is outside 0–{max}°")));
            }
            if let Some(&prev) = angles.last() {
                if a <= prev {
                    return Err(self.error_at(
                        at,
                        format!("{what} angles are not increasing: {a} after {prev}"),
                    ));
                }
            }
            angles.push(a);
        }
        Ok(angles)
    }
}
