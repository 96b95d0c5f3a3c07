//! Byte offsets to line and column, shared by the CLI's JSON and the language server.

/// A position in a source text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Position {
    /// 1-based line number.
    pub line: usize,
    /// 1-based column, counted in characters (Unicode scalar values).
    pub column: usize,
    /// 0-based column counted in UTF-16 code units (what LSP calls `character`).
    pub utf16_column: usize,
}

/// Where a byte range lies, as the machine formats report it (`hstlc check --format json`,
/// the Python package's diagnostics): 1-based lines, columns counted in characters, the
/// end exclusive.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Location {
    /// 1-based line of the start.
    pub line: usize,
    /// 1-based column of the start, in characters.
    pub column: usize,
    /// 1-based line of the end.
    pub end_line: usize,
    /// 1-based column just past the end, in characters.
    pub end_column: usize,
}

/// Maps byte offsets of one source text to [`Position`]s. Lines end at `\n`, `\r\n` or a
/// lone `\r` (as in LSP); a `\r` before `\n` counts as a character of the line.
#[derive(Clone, Debug)]
pub struct LineIndex {
    starts: Vec<usize>,
    len: usize,
}

impl LineIndex {
    /// Indexes `src`.
    pub fn new(src: &str) -> Self {
        let bytes = src.as_bytes();
        let mut starts = vec![0];
        starts.extend(
            bytes
                .iter()
                .enumerate()
                .filter(|&(i, &b)| b == b'\n' || b == b'\r' && bytes.get(i + 1) != Some(&b'\n'))
                .map(|(i, _)| i + 1),
        );
        LineIndex { starts, len: src.len() }
    }

    /// How many lines the text has (one more than its line breaks).
    pub fn line_count(&self) -> usize {
        self.starts.len()
    }

    /// The position of byte `offset` in `src` (the text given to [`LineIndex::new`]).
    /// An offset past the end is clamped to the end; one inside a character is moved back
    /// to the start of that character.
    pub fn position(&self, src: &str, offset: usize) -> Position {
        let mut offset = offset.min(self.len).min(src.len());
        while offset > 0 && !src.is_char_boundary(offset) {
            offset -= 1;
        }
        let line = self.starts.partition_point(|&s| s <= offset).max(1) - 1;
        let start = self.starts[line].min(offset);
        let text = &src[start..offset];
        Position {
            line: line + 1,
            column: text.chars().count() + 1,
            utf16_column: text.chars().map(char::len_utf16).sum(),
        }
    }

    /// The [`Location`] of the byte range `range` of `src`.
    pub fn location(&self, src: &str, range: &std::ops::Range<usize>) -> Location {
        let (start, end) = (self.position(src, range.start), self.position(src, range.end));
        Location {
            line: start.line,
            column: start.column,
            end_line: end.line,
            end_column: end.column,
        }
    }

    /// The byte offset of a 1-based line and 1-based character column, clamped to the line.
    pub fn offset(&self, src: &str, line: usize, column: usize) -> usize {
        let l = line.saturating_sub(1).min(self.starts.len() - 1);
        let start = self.starts[l].min(src.len());
        let end = self.starts.get(l + 1).copied().unwrap_or(src.len()).min(src.len());
        let text = &src[start..end];
        let skip = column.saturating_sub(1);
        start + text.char_indices().nth(skip).map_or(text.len(), |(i, _)| i)
    }

    /// The byte offset of a 0-based line and 0-based UTF-16 column (LSP positions).
    pub fn offset_utf16(&self, src: &str, line: usize, utf16_column: usize) -> usize {
        let l = line.min(self.starts.len() - 1);
        let start = self.starts[l].min(src.len());
        let end = self.starts.get(l + 1).copied().unwrap_or(src.len()).min(src.len());
        let mut units = 0;
        for (i, c) in src[start..end].char_indices() {
            let lone_cr = c == '\r' && src.as_bytes().get(start + i + 1) != Some(&b'\n');
            if units >= utf16_column || c == '\n' || lone_cr {
                return start + i;
            }
            units += c.len_utf16();
        }
        end
    }

    /// The byte range of the 1-based line `line`, without its line break.
    pub fn line_range(&self, src: &str, line: usize) -> std::ops::Range<usize> {
        let l = line.saturating_sub(1).min(self.starts.len() - 1);
        let start = self.starts[l].min(src.len());
        let mut end = self.starts.get(l + 1).copied().unwrap_or(src.len()).min(src.len());
        let bytes = src.as_bytes();
        while end > start && (bytes[end - 1] == b'\n' || bytes[end - 1] == b'\r') {
            end -= 1;
        }
        start..end
    }
}

#[cfg(test)]
mod tests {
    use super::LineIndex;

    /// `(line, column)` of every byte offset of `src`.
    fn positions(src: &str) -> Vec<(usize, usize)> {
        let index = LineIndex::new(src);
        (0..=src.len()).map(|o| index.position(src, o)).map(|p| (p.line, p.column)).collect()
    }

    #[test]
    fn every_line_break_style_starts_a_line() {
        let want = vec![(1, 1), (1, 2), (2, 1), (2, 2), (3, 1)];
        assert_eq!(positions("a\nb\n"), want);
        assert_eq!(positions("a\rb\r"), want);
        // In `\r\n` the `\r` is the line's last character.
        assert_eq!(positions("a\r\nb"), vec![(1, 1), (1, 2), (1, 3), (2, 1), (2, 2)]);
        let src = "a\rb\r\nc\nd";
        let index = LineIndex::new(src);
        assert_eq!(index.line_count(), 4);
        assert_eq!(&src[index.line_range(src, 2)], "b");
        assert_eq!(index.offset_utf16(src, 0, 5), 1);
        // Past the end of a `\r\n` line: its `\n`, as LSP clients count.
        assert_eq!(index.offset_utf16(src, 1, 5), src.find('\n').unwrap());
        assert_eq!(index.offset(src, 3, 1), src.find('c').unwrap());
    }
}
