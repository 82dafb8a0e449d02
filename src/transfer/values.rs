//! Values files: a text matrix with a row per vertex (docs/transfer.md, "Values files").
//!
//! Grammar, checked strictly so that a file is never read as something else:
//! - rows end with `\n` (a `\r` before it is dropped); `#` starts a comment to the end of the
//!   line; lines with nothing but blanks and comments are skipped;
//! - numbers are separated by blanks (spaces, tabs) or by one comma with optional blanks
//!   around it; an empty field (`0.5,,0.25`, a leading or trailing comma) is an error naming
//!   the line and column, never skipped;
//! - outside comments only printable ASCII and tabs: a non-breaking space (U+00A0) or any
//!   other non-ASCII character is an error naming the character, not a separator;
//! - a number is what Rust's `f64` parser reads, finite; an integer (`[+-]digits`) is kept
//!   exactly from $-2^{63}$ to $2^{64}-1$ ([`Values::exact`]) and refused beyond;
//! - every row has as many values as the first.
//!
//! Integers above $2^{53}$ in magnitude, which an `f64` rounds, are carried exactly by
//! [`Values::transfer`] in `Nearest` mode and refused in the modes that average them.

use std::path::Path;

use crate::maps::surface::SurfaceMap;
use crate::shape::io::read_bytes;
use crate::transfer::TransferMode;
use crate::{Error, Result};

/// Largest magnitude up to which every integer is an `f64` exactly: $2^{53}$.
const EXACT_F64: i128 = 1 << 53;

/// A matrix of values, a row per vertex, as read from a values file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Values {
    /// Row-major, `rows x channels`; an integer beyond $\pm 2^{53}$ is here as an `f64`
    /// (maybe rounded), its exact value is in [`Values::exact`].
    values: Vec<f64>,
    channels: usize,
    /// `(index into values, exact integer)` of the integers beyond $\pm 2^{53}$, by index.
    wide: Vec<(usize, i128)>,
}

impl Values {
    /// Values without integers beyond $\pm 2^{53}$: `values` row-major with `channels` a row.
    /// Errors when `channels` is 0 or does not divide the length.
    pub fn from_f64(values: Vec<f64>, channels: usize) -> Result<Values> {
        if channels == 0 || !values.len().is_multiple_of(channels) {
            return Err(Error::InvalidParameter {
                name: "channels",
                reason: format!("{channels} channels do not divide {} values", values.len()),
            });
        }
        Ok(Values {
            values,
            channels,
            wide: Vec::new(),
        })
    }

    /// The number of rows.
    pub fn rows(&self) -> usize {
        self.values.len().checked_div(self.channels).unwrap_or(0)
    }

    /// Values a row.
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// The values as `f64`, row-major; integers beyond $\pm 2^{53}$ rounded.
    pub fn as_f64(&self) -> &[f64] {
        &self.values
    }

    /// The exact value of entry `index` (row-major) when it was read as an integer beyond
    /// $\pm 2^{53}$, else `None`.
    pub fn exact(&self, index: usize) -> Option<i128> {
        self.wide
            .binary_search_by_key(&index, |&(i, _)| i)
            .ok()
            .map(|k| self.wide[k].1)
    }

    /// The rows `rows[i]` of these values, in that order (exact integers kept). Errors on a
    /// row out of range.
    pub fn pick_rows(&self, rows: &[u32]) -> Result<Values> {
        let c = self.channels;
        let mut out = Values {
            values: Vec::with_capacity(rows.len().saturating_mul(c)),
            channels: c,
            wide: Vec::new(),
        };
        for &r in rows {
            let r = r as usize;
            if r >= self.rows() {
                return Err(Error::InvalidParameter {
                    name: "rows",
                    reason: format!("row {r} asked of {} rows", self.rows()),
                });
            }
            let start = self.wide.partition_point(|&(i, _)| i < r * c);
            let end = self.wide.partition_point(|&(i, _)| i < (r + 1) * c);
            let base = out.values.len();
            out.wide.extend(
                self.wide[start..end]
                    .iter()
                    .map(|&(i, v)| (base + i - r * c, v)),
            );
            out.values.extend_from_slice(&self.values[r * c..][..c]);
        }
        Ok(out)
    }

    /// These values, on A's vertices, carried to B's vertices through `onto` by `mode`
    /// ([`SurfaceMap::transfer`]). `Nearest` copies rows, so integers stay exact at any
    /// size; the other modes average, and refuse an integer that an `f64` would change
    /// (beyond $\pm 2^{53}$ and not a multiple of a power of two that the `f64` keeps).
    pub fn transfer(&self, onto: &SurfaceMap, mode: TransferMode) -> Result<Values> {
        if mode == TransferMode::Nearest {
            // The library's checks (row count, finite values), then the rows copied.
            let carried = onto.transfer(&self.values, self.channels, mode)?;
            if self.wide.is_empty() {
                return Values::from_f64(carried, self.channels);
            }
            let nearest: Vec<u32> = onto.points.iter().map(|p| p.nearest()).collect();
            return self.pick_rows(&nearest);
        }
        let changed = self.wide.iter().find(|&&(_, v)| v as f64 as i128 != v);
        if let Some(&(i, v)) = changed {
            return Err(Error::InvalidParameter {
                name: "values_a",
                reason: format!(
                    "vertex {} channel {} is the integer {v}, which a 64-bit float cannot \
                     hold (beyond 2^53): averaging would change it; ids and labels are \
                     carried exactly by the nearest vertex (`nearest` mode)",
                    i / self.channels,
                    i % self.channels
                ),
            });
        }
        let carried = onto.transfer(&self.values, self.channels, mode)?;
        Values::from_f64(carried, self.channels)
    }

    /// The values as text, a line a row, values separated by one space: integers read as
    /// integers beyond $\pm 2^{53}$ exactly as integers, other values in the shortest form
    /// that reads back the same `f64` (with an exponent from $2^{53}$ on, so that a float is
    /// never written as an integer beyond 64 bits). What [`parse_values`] reads back
    /// unchanged.
    pub fn write_text(&self, out: &mut impl std::io::Write) -> std::io::Result<()> {
        let mut wide = self.wide.iter().peekable();
        for (i, x) in self.values.iter().enumerate() {
            let sep = if i % self.channels == 0 { "" } else { " " };
            match wide.next_if(|&&(w, _)| w == i) {
                Some((_, v)) => write!(out, "{sep}{v}")?,
                None if x.abs() >= EXACT_F64 as f64 => write!(out, "{sep}{x:e}")?,
                None => write!(out, "{sep}{x}")?,
            }
            if (i + 1) % self.channels == 0 {
                out.write_all(b"\n")?;
            }
        }
        Ok(())
    }
}

/// Reads a values file of exactly `rows` rows (see the module docs). The file goes through
/// the shape readers' checks first: FIFOs, devices and directories are refused before it is
/// opened, and so is a file above [`crate::shape::io::MAX_FILE_BYTES`].
pub fn read_values(path: &Path, rows: usize) -> Result<Values> {
    parse_values(&read_bytes(path)?, rows, path)
}

/// Parses the bytes of a values file of exactly `rows` rows (see the module docs); `name` is
/// only used in error messages. Stops at the first row beyond `rows`.
pub fn parse_values(bytes: &[u8], rows: usize, name: &Path) -> Result<Values> {
    let error = |line: usize, reason: String| Error::file(name, format!("line {line}: {reason}"));
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let mut out = Values::default();
    let mut count = 0;
    for (i, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let number = i + 1;
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        let line = match line.iter().position(|&b| b == b'#') {
            Some(k) => &line[..k],
            None => line,
        };
        if let Some(k) = line
            .iter()
            .position(|&b| !(b == b'\t' || (b' '..=b'~').contains(&b)))
        {
            return Err(error(number, not_ascii(&line[k..], k + 1)));
        }
        // Only printable ASCII and tabs are left.
        let line = std::str::from_utf8(line).unwrap_or_default();
        let blank = |c: char| c == ' ' || c == '\t';
        if line.trim_matches(blank).is_empty() {
            continue;
        }
        if count == rows {
            return Err(error(
                number,
                format!(
                    "more than {rows} rows of values: shape A has {rows} vertices (one row each)"
                ),
            ));
        }
        let before = out.values.len();
        let pieces: Vec<&str> = line.split(',').collect();
        for (p, piece) in pieces.iter().enumerate() {
            let mut any = false;
            for token in piece.split(blank).filter(|t| !t.is_empty()) {
                any = true;
                let column = out.values.len() - before + 1;
                let index = out.values.len();
                let value = parse_number(token)
                    .map_err(|reason| error(number, format!("column {column}: {reason}")))?;
                match value {
                    Number::Float(x) => out.values.push(x),
                    Number::Wide(v) => {
                        out.values.push(v as f64);
                        out.wide.push((index, v));
                    }
                }
            }
            if !any {
                let column = out.values.len() - before + 1;
                let where_ = if p == 0 {
                    "before the first comma"
                } else if p + 1 == pieces.len() {
                    "after the last comma"
                } else {
                    "between two commas"
                };
                return Err(error(
                    number,
                    format!(
                        "column {column} is empty ({where_}); every row needs a number in \
                         every column"
                    ),
                ));
            }
        }
        let width = out.values.len() - before;
        if count == 0 {
            out.channels = width;
        } else if width != out.channels {
            return Err(error(
                number,
                format!("{width} values, the first row has {}", out.channels),
            ));
        }
        count += 1;
    }
    if count != rows {
        return Err(Error::file(
            name,
            format!("{count} rows of values, but shape A has {rows} vertices (one row each)"),
        ));
    }
    Ok(out)
}

/// A number of a values file.
enum Number {
    /// Any number an `f64` holds exactly as written, or a non-integer one.
    Float(f64),
    /// An integer beyond $\pm 2^{53}$ that fits 64 bits (signed or not).
    Wide(i128),
}

fn parse_number(token: &str) -> std::result::Result<Number, String> {
    let digits = token.strip_prefix(['+', '-']).unwrap_or(token);
    if !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) {
        let too_wide = || {
            format!(
                "the integer {} does not fit 64 bits (from -2^63 to 2^64-1)",
                shown(token)
            )
        };
        let v: i128 = token.parse().map_err(|_| too_wide())?;
        if v < i64::MIN as i128 || v > u64::MAX as i128 {
            return Err(too_wide());
        }
        return Ok(if v.abs() <= EXACT_F64 {
            Number::Float(v as f64)
        } else {
            Number::Wide(v)
        });
    }
    match token.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(Number::Float(x)),
        Ok(_) => Err(format!(
            "`{}` is not a finite number (values must be finite)",
            shown(token)
        )),
        Err(_) => Err(format!("`{}` is not a number", shown(token))),
    }
}

/// Names the character that starts `rest` (at 1-based byte `column` of its line), which is
/// not printable ASCII.
fn not_ascii(rest: &[u8], column: usize) -> String {
    let head = &rest[..rest.len().min(4)];
    let valid = match std::str::from_utf8(head) {
        Ok(s) => s,
        Err(e) => std::str::from_utf8(&head[..e.valid_up_to()]).unwrap_or_default(),
    };
    let what = match valid.chars().next() {
        None => format!("byte 0x{:02X} (not UTF-8 text)", rest[0]),
        Some('\u{A0}') => "U+00A0 (a non-breaking space)".to_string(),
        Some(c) if c.is_ascii() => format!("control character U+{:04X}", c as u32),
        Some(c) => format!("U+{:04X} `{c}`", c as u32),
    };
    format!("byte {column} is {what}; values are numbers separated by ASCII spaces, tabs or commas")
}

/// A token for an error message, cut to 40 characters.
fn shown(token: &str) -> String {
    const MAX: usize = 40;
    match token.char_indices().nth(MAX) {
        Some((k, _)) => format!("{}...", &token[..k]),
        None => token.to_string(),
    }
}

#[cfg(test)]
mod tests;
