//! Why a measured file was rejected: every variant names the file, and
//! where it applies the line and the column.

/// Why a measured file was rejected. Every variant names the file, and where
/// it applies the 1-based line and the column.
#[derive(Debug, thiserror::Error)]
pub enum MeasuredError {
    /// The file could not be opened, read or written.
    #[error("{file}: {error}")]
    Io {
        /// File name as given.
        file: String,
        /// Underlying I/O error.
        error: std::io::Error,
    },
    /// The file has no header row.
    #[error("{file}: no header row (expected `time_s,speed_rpm,current_a,p_a_bar,p_b_bar,ambient_c,...`)")]
    NoHeader {
        /// File name.
        file: String,
    },
    /// A required column is absent from the header.
    #[error("{file}:{line}: missing required column `{column}` in the header")]
    MissingColumn {
        /// File name.
        file: String,
        /// Header line.
        line: u64,
        /// The missing column.
        column: String,
    },
    /// A known column appears twice in the header.
    #[error("{file}:{line}: column `{column}` appears twice in the header")]
    DuplicateColumn {
        /// File name.
        file: String,
        /// Header line.
        line: u64,
        /// The repeated column.
        column: String,
    },
    /// The CSV structure is broken (wrong field count, bad UTF-8, quoting).
    #[error("{file}:{line}: malformed CSV row: {message}")]
    Csv {
        /// File name.
        file: String,
        /// Line of the row.
        line: u64,
        /// Parser message.
        message: String,
    },
    /// A cell is not a number.
    #[error("{file}:{line}: column `{column}`: cannot parse `{value}` as a number (expected a decimal number, or an empty cell for a missing sample)")]
    Unparsable {
        /// File name.
        file: String,
        /// Line of the row.
        line: u64,
        /// Column name.
        column: String,
        /// Cell text.
        value: String,
    },
    /// A cell is NaN or infinite (invalid, not missing).
    #[error("{file}:{line}: column `{column}`: non-finite value `{value}` (NaN and inf are invalid; leave the cell empty for a missing sample)")]
    NonFinite {
        /// File name.
        file: String,
        /// Line of the row.
        line: u64,
        /// Column name.
        column: String,
        /// Cell text.
        value: String,
    },
    /// A value lies outside the physical range of its channel.
    #[error("{file}:{line}: column `{column}`: value {value} {unit} outside the physical range {lo}…{hi} {unit}")]
    OutOfRange {
        /// File name.
        file: String,
        /// Line of the row.
        line: u64,
        /// Column name.
        column: String,
        /// The value.
        value: f64,
        /// Lower bound.
        lo: f64,
        /// Upper bound.
        hi: f64,
        /// Unit of the channel.
        unit: String,
    },
    /// `time_s` is empty in a row (time is never missing).
    #[error("{file}:{line}: column `time_s`: empty cell (every row needs a time)")]
    MissingTime {
        /// File name.
        file: String,
        /// Line of the row.
        line: u64,
    },
    /// `time_s` does not strictly increase.
    #[error("{file}:{line}: column `time_s`: {value} s is not after the previous time {previous} s (time must be strictly increasing)")]
    TimeNotIncreasing {
        /// File name.
        file: String,
        /// Line of the row.
        line: u64,
        /// Previous time, s.
        previous: f64,
        /// This row's time, s.
        value: f64,
    },
    /// A run built in code is inconsistent (channel length differs from time).
    #[error("{file}: channel `{column}` has {got} samples but time_s has {expected}")]
    LengthMismatch {
        /// File name or label.
        file: String,
        /// Channel name.
        column: String,
        /// Samples in the channel.
        got: usize,
        /// Samples in `time_s`.
        expected: usize,
    },
}
