//! Real-time clock readings for the cooling over a power loss's off-time
//! ([`crate::memory::cooling`]): the board reads its calendar registers (BCD,
//! the STM32 RTC's `TR`/`DR` layout) and turns them into seconds since
//! 2000-01-01 00:00 with [`calendar_s`]. Pure and host-tested; the register
//! access lives in the board (`boards/stm32f411/src/rtc.rs`).

/// Seconds since 2000-01-01 00:00:00 of the STM32 RTC's time register `tr`
/// (24-hour format: SU 0-3, ST 4-6, MNU 8-11, MNT 12-14, HU 16-19, HT 20-21)
/// and date register `dr` (DU 0-3, DT 4-5, MU 8-11, MT 12, YU 16-19,
/// YT 20-23). `None` for a digit that is not BCD or a field out of range
/// (a calendar never initialised or corrupted: no off-time, no cooling).
pub fn calendar_s(tr: u32, dr: u32) -> Option<u32> {
    let bcd = |v: u32, lo: u32, tens_bits: u32| -> Option<u32> {
        let units = (v >> lo) & 0xF;
        let tens = (v >> (lo + 4)) & ((1 << tens_bits) - 1);
        (units <= 9).then_some(tens * 10 + units)
    };
    let sec = bcd(tr, 0, 3)?;
    let min = bcd(tr, 8, 3)?;
    let hour = bcd(tr, 16, 2)?;
    let day = bcd(dr, 0, 2)?;
    let month = bcd(dr, 8, 1)?;
    let year = bcd(dr, 16, 4)?;
    if tr & (1 << 22) != 0 || sec > 59 || min > 59 || hour > 23 || !(1..=12).contains(&month) || year > 99 {
        return None;
    }
    if day < 1 || day > days_in_month(2000 + year, month) {
        return None;
    }
    let days = days_since_2000(2000 + year, month, day);
    Some(days * 86_400 + hour * 3600 + min * 60 + sec)
}

fn leap(y: u32) -> bool {
    (y.is_multiple_of(4) && !y.is_multiple_of(100)) || y.is_multiple_of(400)
}

fn days_in_month(y: u32, m: u32) -> u32 {
    match m {
        2 if leap(y) => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    }
}

/// Days from 2000-01-01 to `y-m-d` (`y` in 2000..=2099).
fn days_since_2000(y: u32, m: u32, d: u32) -> u32 {
    let mut days = 0;
    for yy in 2000..y {
        days += if leap(yy) { 366 } else { 365 };
    }
    for mm in 1..m {
        days += days_in_month(y, mm);
    }
    days + d - 1
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tr(h: u32, m: u32, s: u32) -> u32 {
        ((h / 10) << 20) | ((h % 10) << 16) | ((m / 10) << 12) | ((m % 10) << 8) | ((s / 10) << 4) | (s % 10)
    }
    fn dr(y: u32, mo: u32, d: u32) -> u32 {
        ((y / 10) << 20) | ((y % 10) << 16) | ((mo / 10) << 12) | ((mo % 10) << 8) | ((d / 10) << 4) | (d % 10)
    }

    /// The reset value of the date register (2000-01-01, Monday) is 0.
    #[test]
    fn epoch_and_known_dates() {
        assert_eq!(calendar_s(0, 0x0000_2101), Some(0));
        assert_eq!(calendar_s(tr(23, 59, 59), dr(0, 1, 1)), Some(86_399));
        // 2000 is a leap year: 2000-03-01 is day 60
        assert_eq!(calendar_s(0, dr(0, 3, 1)), Some(60 * 86_400));
        // 2026-11-23 12:34:56 = Unix 1795437296 minus Unix 946684800 (2000-01-01)
        assert_eq!(calendar_s(tr(12, 34, 56), dr(26, 11, 23)), Some(1_795_437_296 - 946_684_800));
    }

    /// Non-BCD digits and impossible dates give no reading.
    #[test]
    fn garbage_gives_none() {
        assert_eq!(calendar_s(0x0000_000A, dr(0, 1, 1)), None);
        assert_eq!(calendar_s(tr(24, 0, 0), dr(0, 1, 1)), None);
        assert_eq!(calendar_s(0, dr(1, 2, 29)), None);
        assert_eq!(calendar_s(0, dr(0, 13, 1)), None);
        assert_eq!(calendar_s(0, dr(0, 1, 0)), None);
        assert_eq!(calendar_s(1 << 22, dr(0, 1, 1)), None);
    }

    /// A later calendar time reads more seconds (off-times are differences).
    #[test]
    fn monotone_over_a_month_boundary() {
        let a = calendar_s(tr(23, 0, 0), dr(25, 2, 28));
        let b = calendar_s(tr(1, 0, 0), dr(25, 3, 1));
        assert_eq!(b.zip(a).map(|(b, a)| b - a), Some(7200));
    }
}
