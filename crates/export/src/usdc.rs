//! Binary USD layers (`.usdc`, USD's "crate" file format).
//!
//! The crate file is written by `openusd` 0.6's `CrateWriter`, the last
//! version of that library that builds with this project's Rust. It has one
//! flaw Pixar's USD trips over (fixed upstream in 0.8): it stores the lists
//! of a spec's children (`primChildren`, `properties`, …), which USD types
//! as a token *vector*, as token *arrays*. The bytes of the two are the same
//! (a `u64` count and one `u32` token index per name); only the value's type
//! code and its "array" flag differ. USD reads a child list of the wrong
//! type as no list at all, so every prim below the root went missing.
//! [`retype_child_lists`] corrects those type codes in the written file.
//!
//! What it relies on, from the format's published description (USD's
//! `crateFile.h` and the openusd crate's reader):
//! - the file starts with `PXR-USDC`, the version bytes and, at byte 16,
//!   the offset of the table of contents (a `u64` count, then per section a
//!   16-byte name, a `u64` start and a `u64` size);
//! - `TOKENS`: the token count, the size of the null-separated names, then
//!   the names compressed;
//! - `FIELDS`: the field count, the fields' token indices as compressed
//!   integers, then the fields' values (`ValueRep`, one `u64` each:
//!   payload in the low 48 bits, type code in bits 48–55, "compressed",
//!   "inlined" and "array" flags in bits 61, 62 and 63) compressed;
//! - "compressed" is a `u64` byte count, then one byte giving the number of
//!   extra chunks (0: a single block) and an LZ4 block;
//! - compressed integers (USD's integer coding) are a common delta (`i32`),
//!   two code bits per integer (0 the common delta, 1–3 an `i8`, `i16` or
//!   `i32` delta that follows), deltas from the previous integer (from 0).
//!
//! The corrected `FIELDS` section is written where the table of contents
//! was, followed by a new table of contents; the old section stays behind
//! unreferenced (a few hundred bytes).

use std::io::Cursor;

use openusd::sdf;

use crate::ExportError;

const MAGIC: &[u8; 8] = b"PXR-USDC";
/// Type codes of a `ValueRep` (USD's `crateDataTypes.h`).
const TYPE_TOKEN: u64 = 11;
const TYPE_TOKEN_VECTOR: u64 = 41;
const ARRAY_BIT: u64 = 1 << 63;
const TYPE_SHIFT: u32 = 48;
const TYPE_MASK: u64 = 0xff << TYPE_SHIFT;

/// Fields USD stores as a token vector (`std::vector<TfToken>`), under
/// their names in a crate file (the property children are `properties`
/// there).
const TOKEN_VECTOR_FIELDS: [&str; 8] = [
    "primChildren",
    "properties",
    "variantChildren",
    "variantSetChildren",
    "expressionChildren",
    "mapperArgChildren",
    "primOrder",
    "propertyOrder",
];

fn crate_error(what: impl std::fmt::Display) -> ExportError {
    ExportError::Usd(format!("writing the .usdc file: {what}"))
}

/// The crate file of `data`, with its child lists typed as USD reads them.
pub(crate) fn crate_bytes(data: &sdf::Data) -> Result<Vec<u8>, ExportError> {
    let mut out = Cursor::new(Vec::new());
    openusd::usdc::CrateWriter::write(data, &mut out).map_err(crate_error)?;
    retype_child_lists(out.into_inner())
}

/// A little-endian reader over a byte slice that fails instead of
/// panicking at the end.
struct Bytes<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Bytes<'a> {
    fn at(bytes: &'a [u8], at: usize) -> Bytes<'a> {
        Bytes { bytes, at }
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8], ExportError> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end = end.ok_or_else(|| crate_error(format!("truncated at byte {}", self.at)))?;
        let slice = &self.bytes[self.at..end];
        self.at = end;
        Ok(slice)
    }

    fn u64(&mut self) -> Result<u64, ExportError> {
        let mut b = [0u8; 8];
        b.copy_from_slice(self.take(8)?);
        Ok(u64::from_le_bytes(b))
    }

    fn len(&mut self) -> Result<usize, ExportError> {
        usize::try_from(self.u64()?).map_err(crate_error)
    }

    /// A compressed block: its byte count, then the block.
    fn compressed(&mut self) -> Result<&'a [u8], ExportError> {
        let n = self.len()?;
        self.take(n)
    }
}

/// One section of the table of contents.
struct Section {
    name: [u8; 16],
    start: u64,
    size: u64,
}

impl Section {
    fn named(&self, name: &str) -> bool {
        let end = self.name.iter().position(|&b| b == 0).unwrap_or(16);
        &self.name[..end] == name.as_bytes()
    }
}

/// Decompresses a block written as one LZ4 block behind a zero chunk count,
/// into at most `capacity` bytes.
fn decompress(block: &[u8], capacity: usize) -> Result<Vec<u8>, ExportError> {
    match block.split_first() {
        Some((0, lz4)) => {
            let mut out = vec![0u8; capacity];
            let n = lz4_flex::block::decompress_into(lz4, &mut out).map_err(crate_error)?;
            out.truncate(n);
            Ok(out)
        }
        _ => Err(crate_error("a compressed block of several chunks")),
    }
}

fn compress(bytes: &[u8]) -> Vec<u8> {
    let mut block = vec![0u8];
    block.extend_from_slice(&lz4_flex::block::compress(bytes));
    block
}

/// Decodes `count` integers of USD's integer coding (32-bit form).
fn decode_u32s(coded: &[u8], count: usize) -> Result<Vec<u32>, ExportError> {
    let mut codes = Bytes::at(coded, 0);
    let common = i64::from(i32::from_le_bytes(
        codes.take(4)?.try_into().map_err(crate_error)?,
    ));
    let code_bytes = codes.take((2 * count).div_ceil(8))?;
    let mut deltas = Bytes::at(coded, codes.at);
    let mut previous = 0i64;
    let mut values = Vec::with_capacity(count);
    for i in 0..count {
        let code = (code_bytes[i / 4] >> (2 * (i % 4))) & 3;
        let delta = match code {
            0 => common,
            1 => i64::from(i8::from_le_bytes([deltas.take(1)?[0]])),
            2 => i64::from(i16::from_le_bytes(
                deltas.take(2)?.try_into().map_err(crate_error)?,
            )),
            _ => i64::from(i32::from_le_bytes(
                deltas.take(4)?.try_into().map_err(crate_error)?,
            )),
        };
        previous += delta;
        values.push(u32::try_from(previous).map_err(crate_error)?);
    }
    Ok(values)
}

/// The token names of the `TOKENS` section.
fn tokens(file: &[u8], section: &Section) -> Result<Vec<String>, ExportError> {
    let mut r = Bytes::at(file, usize::try_from(section.start).map_err(crate_error)?);
    let count = r.len()?;
    let size = r.len()?;
    let names = decompress(r.compressed()?, size)?;
    let tokens: Vec<String> = names
        .split(|&b| b == 0)
        .take(count)
        .map(|name| String::from_utf8_lossy(name).into_owned())
        .collect();
    if tokens.len() != count {
        return Err(crate_error("fewer token names than the token count"));
    }
    Ok(tokens)
}

/// Gives every token-array value of a [`TOKEN_VECTOR_FIELDS`] field the
/// token-vector type in the crate file `file` (see the module
/// documentation).
pub(crate) fn retype_child_lists(mut file: Vec<u8>) -> Result<Vec<u8>, ExportError> {
    let mut header = Bytes::at(&file, 0);
    if header.take(8)? != MAGIC {
        return Err(crate_error("not a crate file"));
    }
    header.take(8)?;
    let toc_at = header.len()?;
    let mut toc = Bytes::at(&file, toc_at);
    let section_count = toc.len()?;
    let mut sections = Vec::with_capacity(section_count.min(64));
    for _ in 0..section_count {
        let name: [u8; 16] = toc.take(16)?.try_into().map_err(crate_error)?;
        let start = toc.u64()?;
        let size = toc.u64()?;
        sections.push(Section { name, start, size });
    }
    let find = |name: &str| {
        sections
            .iter()
            .position(|s| s.named(name))
            .ok_or_else(|| crate_error(format!("no {name} section")))
    };
    let tokens = tokens(&file, &sections[find("TOKENS")?])?;
    let fields_index = find("FIELDS")?;

    let mut r = Bytes::at(
        &file,
        usize::try_from(sections[fields_index].start).map_err(crate_error)?,
    );
    let field_count = r.len()?;
    let token_block_at = r.at;
    let token_block = r.compressed()?;
    let token_block_len = r.at - token_block_at;
    let coded_capacity = 4 + (2 * field_count).div_ceil(8) + 4 * field_count;
    let field_tokens = decode_u32s(&decompress(token_block, coded_capacity)?, field_count)?;
    let reps_bytes = decompress(r.compressed()?, 8 * field_count)?;
    if reps_bytes.len() != 8 * field_count {
        return Err(crate_error("the field values do not match the field count"));
    }
    let mut reps: Vec<u64> = reps_bytes
        .chunks_exact(8)
        .map(|c| u64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
        .collect();

    for (rep, token) in reps.iter_mut().zip(&field_tokens) {
        let name = tokens
            .get(*token as usize)
            .ok_or_else(|| crate_error(format!("token index {token} out of range")))?;
        let token_array = (*rep & TYPE_MASK) >> TYPE_SHIFT == TYPE_TOKEN && *rep & ARRAY_BIT != 0;
        if token_array && TOKEN_VECTOR_FIELDS.contains(&name.as_str()) {
            *rep = (*rep & !TYPE_MASK & !ARRAY_BIT) | (TYPE_TOKEN_VECTOR << TYPE_SHIFT);
        }
    }

    // The new FIELDS section: the same token indices, the corrected values.
    let mut fields = Vec::new();
    fields.extend_from_slice(&(field_count as u64).to_le_bytes());
    fields.extend_from_slice(&file[token_block_at..token_block_at + token_block_len]);
    let reps_block = compress(
        &reps
            .iter()
            .flat_map(|r| r.to_le_bytes())
            .collect::<Vec<_>>(),
    );
    fields.extend_from_slice(&(reps_block.len() as u64).to_le_bytes());
    fields.extend_from_slice(&reps_block);

    file.truncate(toc_at);
    sections[fields_index].start = toc_at as u64;
    sections[fields_index].size = fields.len() as u64;
    file.extend_from_slice(&fields);
    let new_toc_at = file.len() as u64;
    file.extend_from_slice(&(sections.len() as u64).to_le_bytes());
    for section in &sections {
        file.extend_from_slice(&section.name);
        file.extend_from_slice(&section.start.to_le_bytes());
        file.extend_from_slice(&section.size.to_le_bytes());
    }
    file[16..24].copy_from_slice(&new_toc_at.to_le_bytes());
    Ok(file)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integer_coding_decodes_common_small_and_medium_deltas() {
        // 5, 6, 7, 300: deltas 5 (i8), 1 and 1 (the common delta), 293
        // (i16); codes 1, 0, 0, 2 from the low bits up.
        let coded = [1, 0, 0, 0, 0b1000_0001, 5, 0x25, 0x01];
        assert_eq!(decode_u32s(&coded, 4).expect("decodes"), vec![5, 6, 7, 300]);
        assert!(decode_u32s(&coded[..6], 4).is_err(), "truncated");
    }

    #[test]
    fn a_file_that_is_not_a_crate_file_is_an_error() {
        let error = retype_child_lists(b"#usda 1.0\n".to_vec()).expect_err("text");
        assert!(error.to_string().contains(".usdc"), "{error}");
    }
}
