//! Byte offsets <-> LSP positions, in the negotiated encoding.

use hstl::lang::LineIndex;
use lsp_types::{Position, Range};

/// How the client counts characters in a line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// Bytes of UTF-8.
    Utf8,
    /// UTF-16 code units, the protocol's default.
    Utf16,
}

/// Converts positions of one text; built once per version of a document, so that each
/// conversion is a binary search plus a scan of one line.
#[derive(Clone, Debug)]
pub struct Converter {
    index: LineIndex,
    lines: usize,
    enc: Encoding,
}

impl Converter {
    /// Indexes `text` for the encoding `enc`.
    pub fn new(text: &str, enc: Encoding) -> Self {
        let lines = text.bytes().filter(|&b| b == b'\n').count() + 1;
        Converter { index: LineIndex::new(text), lines, enc }
    }

    /// The LSP position of byte `offset` (clamped to the text, snapped back to a
    /// character boundary).
    pub fn position(&self, text: &str, offset: usize) -> Position {
        let p = self.index.position(text, offset);
        let character = match self.enc {
            Encoding::Utf16 => p.utf16_column,
            Encoding::Utf8 => {
                let mut offset = offset.min(text.len());
                while !text.is_char_boundary(offset) {
                    offset -= 1;
                }
                offset - self.index.line_range(text, p.line).start
            }
        };
        Position::new((p.line - 1) as u32, character as u32)
    }

    /// The LSP range of a byte range.
    pub fn range(&self, text: &str, r: &std::ops::Range<usize>) -> Range {
        Range::new(self.position(text, r.start), self.position(text, r.end))
    }

    /// The byte offset of an LSP position: past the end of a line it is the line's end,
    /// past the last line it is the end of the text; inside a character it is that
    /// character's end.
    pub fn offset(&self, text: &str, pos: Position) -> usize {
        let line = pos.line as usize;
        if line >= self.lines {
            return text.len();
        }
        match self.enc {
            Encoding::Utf16 => self.index.offset_utf16(text, line, pos.character as usize),
            Encoding::Utf8 => {
                let start = self.index.line_range(text, line + 1).start;
                let end = text[start..].find('\n').map_or(text.len(), |i| start + i);
                let mut at = (start + pos.character as usize).min(end);
                while !text.is_char_boundary(at) {
                    at += 1;
                }
                at
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utf16_counts_surrogate_pairs_and_round_trips() {
        let text = "let é = 1;\n// 𝛼 x\r\ny";
        let x = text.find('x').unwrap();
        let c16 = Converter::new(text, Encoding::Utf16);
        let c8 = Converter::new(text, Encoding::Utf8);
        assert_eq!(c16.position(text, x), Position::new(1, 6));
        assert_eq!(c8.position(text, x), Position::new(1, 8));
        for c in [&c8, &c16] {
            for (i, _) in text.char_indices() {
                assert_eq!(c.offset(text, c.position(text, i)), i, "offset {i}");
            }
            assert_eq!(c.offset(text, Position::new(9, 0)), text.len());
            assert_eq!(c.offset(text, Position::new(0, 99)), text.find('\n').unwrap());
        }
        assert_eq!(c16.position(text, text.len()), Position::new(2, 1));
    }
}
