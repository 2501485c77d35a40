//! [`MapError`]: why a map file (any format) or a value that refers to it could not be used.
//! `Display` is one line naming the file.

use super::bitmap::MAX_SIDE;

/// Why a map could not be loaded. `Display` is one line: file, line number, problem.
#[derive(Debug, thiserror::Error)]
pub enum MapError {
    /// The file could not be read (missing, a directory, no permission, ...).
    #[error("{path}: cannot read the file: {source}")]
    Unreadable {
        /// The file as given.
        path: String,
        /// What the operating system said.
        #[source]
        source: std::io::Error,
    },
    /// A problem with a ROS YAML file or an image, or with a value that refers to the map
    /// (a position in metres, a cell size).
    #[error("{path}: {problem}")]
    File {
        /// The file as given.
        path: String,
        /// What is wrong.
        problem: String,
    },
    /// The text of a Moving AI or text-grid file is not a valid map.
    #[error("{path}, line {line}: {problem}")]
    Parse {
        /// The file as given (or the name passed to [`Map::parse`](super::Map::parse)).
        path: String,
        /// 1-based line number the problem was found on.
        line: usize,
        /// What is wrong.
        problem: Problem,
    },
}

impl MapError {
    /// The parse problem, if the file was readable.
    pub fn problem(&self) -> Option<&Problem> {
        match self {
            MapError::Parse { problem, .. } => Some(problem),
            MapError::Unreadable { .. } | MapError::File { .. } => None,
        }
    }

    /// The 1-based line number of a parse problem.
    pub fn line(&self) -> Option<usize> {
        match self {
            MapError::Parse { line, .. } => Some(*line),
            MapError::Unreadable { .. } | MapError::File { .. } => None,
        }
    }
}

/// What is wrong with a map's content.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum Problem {
    /// A Moving AI header line is not what it should be.
    #[error("wrong header: expected `{expected}`, found `{found}`")]
    WrongHeader {
        /// The line that was expected, e.g. `type octile` or `height <rows>`.
        expected: &'static str,
        /// The line found (trimmed).
        found: String,
    },
    /// The file ends inside the Moving AI header.
    #[error("truncated map: the file ends before the header line `{expected}`")]
    TruncatedHeader {
        /// The header line that is missing.
        expected: &'static str,
    },
    /// The file ends before the header's number of rows.
    #[error("truncated map: expected {expected} rows, found {found}")]
    TruncatedRows {
        /// Rows the header announced.
        expected: usize,
        /// Rows present.
        found: usize,
    },
    /// A row has a different number of cells than the width (Moving AI) or the first row (text).
    #[error("row {row} has {found} cells, expected {expected}")]
    RowLength {
        /// 1-based row number.
        row: usize,
        /// Cells expected.
        expected: usize,
        /// Cells found.
        found: usize,
    },
    /// A text grid holds a character other than `.`, `0`, `#`, `1`.
    #[error("unknown character {ch:?} in column {column} (free: `.` `0`, blocked: `#` `1`)")]
    UnknownChar {
        /// The character.
        ch: char,
        /// 1-based column.
        column: usize,
    },
    /// A side is longer than 65535 cells.
    #[error("map too large: {side} {value} is more than {max}", max = MAX_SIDE)]
    TooLarge {
        /// `width` or `height`.
        side: &'static str,
        /// The value given or counted.
        value: String,
    },
    /// A Moving AI header gives a side of 0.
    #[error("empty map: {side} is 0")]
    ZeroSide {
        /// `width` or `height`.
        side: &'static str,
    },
    /// A text grid file holds no rows.
    #[error("empty map: no rows")]
    Empty,
    /// A text grid has a blank line before its last row.
    #[error("blank line inside the map")]
    BlankLine,
    /// A Moving AI file has more rows than its header's height.
    #[error("more rows than the header's height {height}")]
    ExtraRow {
        /// The header's height.
        height: usize,
    },
}
