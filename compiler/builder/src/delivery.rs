//! How a built program reaches its control (the machine's `delivery`): a
//! program larger than the control's file limit (or, loaded into memory,
//! than its memory) is split into parts a main program calls
//! (`lensc_runtime::post::split`), and the split set is read back as the
//! control runs it (`reader::parts`) and must make the very moves the
//! whole program made; a program that consumes more bytes per second
//! while it cuts than its link delivers is warned of (W0050): on average
//! over its cutting time, or over a stretch of short blocks that would
//! empty the control's buffer while the tool is on the part.

use lensc_grammar::Diagnostic;
use lensc_lang::codes;
use lensc_lang::schema::machines::DeliveryParams;
use lensc_runtime::post::split::{SplitError, split};
use lensc_runtime::reader::timing::{LineTime, line_times};
use lensc_runtime::reader::{self, MachineLimits};

use crate::job::JobHead;
use crate::output::{Built, ProgramText};
use crate::report;

/// The bytes each program file may hold under `d`: its `file_limit`, and
/// with `link: memory` its `memory` too (the smaller); `None`: no limit.
pub fn file_limit(
    d: &DeliveryParams,
) -> Option<(u64, (lensc_grammar::FileId, lensc_grammar::Span))> {
    let memory = d.memory.filter(|_| d.link.value == "memory");
    [d.file_limit, memory]
        .into_iter()
        .flatten()
        .min_by(|a, b| a.value.total_cmp(&b.value))
        .map(|s| (s.value.floor() as u64, s.site))
}

/// The bytes per second the link delivers: `rate` as stated, else a
/// serial link's baud / 10 (start bit, 8 data bits, stop bit); `None` for
/// a program loaded into memory or read from the control's disk, and for
/// a data server that states no rate.
pub fn link_rate(d: &DeliveryParams) -> Option<f64> {
    match d.link.value {
        "dnc" => d.rate.map(|r| r.value).or(d.baud.map(|b| b.value / 10.0)),
        "data_server" => d.rate.map(|r| r.value),
        _ => None,
    }
}

/// Splits `b`'s program into parts if it is larger than the machine's
/// delivery allows, reads the set back as one program and checks it moves
/// as the whole did; the main program takes the program's place and the
/// parts go beside it, written in one unit with it. `lathe`: the machine
/// is a lathe (for the reader).
pub fn deliver(head: &JobHead, b: &mut Built, lathe: bool) -> Result<(), Vec<Diagnostic>> {
    let Some(d) = &head.delivery else {
        return Ok(());
    };
    let Some((limit, site)) = file_limit(d) else {
        return Ok(());
    };
    let whole_bytes = b.program.bytes();
    if whole_bytes <= limit {
        return Ok(());
    }
    let text = b.program.text().map_err(|e| {
        vec![head.error(
            codes::CANNOT_WRITE,
            format!("{} could not be read to split it: {e}", head.program_name()),
        )]
    })?;
    let at = |code, msg: String| Diagnostic::error(code, msg, site.0, site.1);
    let what = format!(
        "the program {} is {} bytes, more than the {limit} bytes the machine's `delivery` allows a file",
        head.program_name(),
        whole_bytes
    );
    let split = match split(&text, &head.dialect, &head.name, limit) {
        Ok(Some(s)) => s,
        Ok(None) => return Ok(()),
        Err(SplitError::NoPartCalls) => {
            return Err(vec![at(
                codes::CANNOT_SPLIT,
                format!(
                    "{what}, and the dialect `{}` calls no parts to split it into",
                    head.dialect.name
                ),
            )
            .with_label("this limit")
            .with_help("give the dialect a `part_call` (with `part_start` and `part_end`; its blocks unnumbered), raise the limit, or make the program smaller")]);
        }
        Err(SplitError::HeaderOverLimit { needed }) => {
            return Err(vec![at(
                codes::FILE_LIMIT_BELOW_PART,
                format!(
                    "{what}, and a part's own lines (opening, closing, the modal words it restates) with one block take {needed} bytes: no part fits"
                ),
            )
            .with_label("this limit")
            .with_help(format!("a file limit of at least {needed} bytes (a control's real limit is megabytes)"))]);
        }
        Err(SplitError::NoJoin {
            from,
            to,
            bytes,
            needed,
        }) => {
            let stops = !head.dialect.parts.as_ref().is_some_and(|p| p.continuous);
            return Err(vec![at(
                codes::NO_SAFE_JOIN,
                format!(
                    "{what}, and lines {from} to {to} ({bytes} bytes) have no join within it: {}",
                    if stops {
                        "the control stops between parts (`part_joins: retract`), so a part may end only after a retract, and this cut is longer than a part"
                    } else {
                        "no two moves there to end a part between"
                    }
                ),
            )
            .with_label("this limit")
            .with_help(format!(
                "raise the file limit to at least {needed} bytes (this cut with a part's own lines), stream the program (`link: data_server` with a larger `file_limit`), or shorten the cut"
            ))]);
        }
    };
    // The set read back as the control runs it: the main program's calls
    // followed, and every move the same as the whole program's.
    let parts = split.parts.clone();
    let mut load = |name: &str| -> Result<String, String> {
        parts
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, t)| t.clone())
            .ok_or_else(|| "not among the parts written".to_string())
    };
    let machine = MachineLimits {
        lathe,
        travel: [None; 4],
        max_feed: None,
        max_spindle_rpm: None,
        servo: head.servo,
    };
    let assembled = reader::parts::assemble(&split.main, &head.dialect, &head.name, &mut load)
        .map_err(|e| vec![head.error(codes::SPLIT_READS_DIFFERENTLY, e.message())])?;
    let (found, moves) = reader::read_moves(&assembled, &head.dialect, &machine);
    let (_, whole) = reader::read_moves(&text, &head.dialect, &machine);
    if moves != whole || !found.is_empty() {
        let first = moves.iter().zip(&whole).position(|(a, b)| a != b);
        return Err(vec![head.error(
            codes::SPLIT_READS_DIFFERENTLY,
            format!(
                "the program split into {} parts does not read back as the whole: {} moves against {}{}{}",
                split.parts.len(),
                moves.len(),
                whole.len(),
                first.map_or(String::new(), |i| format!(", the first different the {}th", i + 1)),
                found
                    .first()
                    .map_or(String::new(), |f| format!("; line {}: {}", f.line, f.message))
            ),
        )
        .with_help("a fault of lensc's splitter; nothing was written")]);
    }
    b.report.program.lines = split.main.lines().count();
    b.report.program.bytes = split.main.len() as u64;
    b.report.program.delivery = Some(report::Delivery {
        limit,
        whole_bytes,
        parts: split
            .parts
            .iter()
            .map(|(file, t)| report::Part {
                file: file.clone(),
                bytes: t.len() as u64,
            })
            .collect(),
    });
    b.program = ProgramText::Memory(split.main);
    // The parts before the main program in the unit: a main program on
    // disk always has its parts beside it.
    let mut beside: Vec<(String, ProgramText)> = split
        .parts
        .into_iter()
        .map(|(n, t)| (n, ProgramText::Memory(t)))
        .collect();
    beside.append(&mut b.beside);
    b.beside = beside;
    Ok(())
}

/// W0050 when the program consumes more bytes per second, on average over
/// its cutting time (all its bytes over the time the control runs it),
/// than the machine's link delivers: the control's buffer would run dry
/// and the tool stop on the part. The average is the least the link must
/// carry; a stretch of short blocks asks more ([`peak_warning`]).
pub fn rate_warning(head: &JobHead, b: &Built) -> Option<Diagnostic> {
    let d = head.delivery.as_ref()?;
    let rate = link_rate(d)?;
    let bytes = b.program.bytes() + b.beside.iter().map(|(_, t)| t.bytes()).sum::<u64>();
    let time = b.cutting_time;
    if time.is_nan() || time <= 0.0 || bytes == 0 {
        return None;
    }
    let needs = bytes as f64 / time;
    if needs <= rate {
        return None;
    }
    let fits = rate / needs;
    let site = d.rate.or(d.baud).map_or(d.link.site, |s| s.site);
    Some(
        Diagnostic::warning(
            codes::LINK_TOO_SLOW,
            format!(
                "the program needs {} a second on average ({} bytes over {} of cutting), more than the {} a second its `{}` link delivers: the control would run out of program and stop on the part",
                bytes_text(needs),
                bytes,
                lensc_lang::check::trim_num((time * 10.0).round() / 10.0) + " s",
                bytes_text(rate),
                d.link.value
            ),
            site.0,
            site.1,
        )
        .with_label("this link")
        .with_help(format!(
            "the feed that fits is {:.0} % of the planned one (a cutting time of at least {:.0} s): slow the feed (and a servo's spindle) to it, or use a faster link",
            (fits * 100.0).floor(),
            (bytes as f64 / rate).ceil()
        )),
    )
}

/// The bytes of program a control holds ahead of the block it runs when
/// the machine states none (`delivery.buffer`): an assumption, about a
/// hundred blocks of forty bytes (Fanuc's multi-buffer reads up to 100
/// blocks ahead; docs/language/delivery.md).
pub const ASSUMED_BUFFER: f64 = 4096.0;

/// Where a streamed program first runs its control's buffer dry while the
/// tool cuts: the stretch of lines (0-based, `first..=last`) consumed since
/// the buffer was last full, its bytes and cutting seconds, and the line
/// the control waits for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Starved {
    pub first: usize,
    pub last: usize,
    pub bytes: u64,
    pub seconds: f64,
}

/// Runs the control over `lines` fed at `rate` bytes a second into a
/// buffer of `buffer` bytes, each line's time multiplied by `stretch` (a
/// feed divided by it): the control takes a line once all its bytes have
/// arrived, and the link fills the buffer while the control runs. A wait
/// in the air (after a rapid, before the first cut) costs nothing, and
/// each cut starts with the buffer full (an assumption: the control may
/// wait there for it at no cost to the part); the first wait after a feed
/// move, before the next rapid (a stop with the tool on the part), is
/// returned.
pub fn starved(lines: &[LineTime], rate: f64, buffer: f64, stretch: f64) -> Option<Starved> {
    let mut avail = buffer;
    let mut cutting = false;
    // The first line consumed since the buffer was last full.
    let mut since = 0usize;
    for (i, l) in lines.iter().enumerate() {
        let need = f64::from(l.bytes).min(buffer);
        if avail < need {
            if cutting {
                let stretch_lines = &lines[since..=i];
                return Some(Starved {
                    first: since,
                    last: i,
                    bytes: stretch_lines.iter().map(|l| u64::from(l.bytes)).sum(),
                    seconds: stretch_lines[..stretch_lines.len() - 1]
                        .iter()
                        .map(|l| l.seconds * stretch)
                        .sum(),
                });
            }
            avail = buffer;
            since = i;
        }
        avail -= need;
        avail = (avail + rate * l.seconds * stretch).min(buffer);
        if avail >= buffer {
            since = i + 1;
        }
        if l.rapid {
            cutting = false;
        } else if l.feed {
            cutting = true;
        }
    }
    None
}

/// W0050 when a stretch of the program, at the planned feed, needs more
/// bytes a second than the link delivers for longer than the control's
/// buffer covers (`delivery.buffer`, else [`ASSUMED_BUFFER`]): the
/// control would wait for its next block with the tool on the part. Read
/// from the whole program's text (`lathe`: the machine is a lathe), before
/// it is split; `None` for a link that states no rate, or where the
/// average rate is already too high (`rate_warning` says so).
pub fn peak_warning(head: &JobHead, b: &Built, lathe: bool) -> Option<Diagnostic> {
    let d = head.delivery.as_ref()?;
    let rate = link_rate(d)?;
    let buffer = d.buffer.map_or(ASSUMED_BUFFER, |s| s.value);
    let text = b.program.text().ok()?;
    let machine = MachineLimits {
        lathe,
        travel: [None; 4],
        max_feed: None,
        max_spindle_rpm: None,
        servo: head.servo,
    };
    let lines = line_times(&text, &head.dialect, &machine);
    let total: f64 = lines.iter().map(|l| f64::from(l.bytes)).sum();
    if b.cutting_time > 0.0 && total / b.cutting_time > rate {
        return None;
    }
    let s = starved(&lines, rate, buffer, 1.0)?;
    // The feed that fits: the least stretch of every line's time (found
    // by halving) at which the control never waits on the part.
    let (mut low, mut high) = (1.0f64, 2.0f64);
    while starved(&lines, rate, buffer, high).is_some() && high < 1e6 {
        (low, high) = (high, high * 2.0);
    }
    let fits = if starved(&lines, rate, buffer, high).is_some() {
        None
    } else {
        for _ in 0..30 {
            let mid = 0.5 * (low + high);
            if starved(&lines, rate, buffer, mid).is_some() {
                low = mid;
            } else {
                high = mid;
            }
        }
        Some(1.0 / high)
    };
    let buffer_words = match d.buffer {
        Some(_) => format!("its buffer of {buffer} bytes"),
        None => format!(
            "a buffer of {buffer} bytes (assumed: the machine's `delivery` states no `buffer`)"
        ),
    };
    let site = d
        .buffer
        .or(d.rate)
        .or(d.baud)
        .map_or(d.link.site, |s| s.site);
    let needs = if s.seconds > 0.0 {
        format!("{} a second", bytes_text(s.bytes as f64 / s.seconds))
    } else {
        "its bytes in no time".to_string()
    };
    Some(
        Diagnostic::warning(
            codes::LINK_TOO_SLOW,
            format!(
                "lines {} to {} of {} need {needs} ({} bytes over {} of cutting), more than the {} a second its `{}` link delivers for longer than {buffer_words} covers: the control would wait for line {} with the tool on the part",
                s.first + 1,
                s.last + 1,
                head.program_name(),
                s.bytes,
                seconds_text(s.seconds),
                bytes_text(rate),
                d.link.value,
                s.last + 1,
            ),
            site.0,
            site.1,
        )
        .with_label("this link")
        .with_help(match fits {
            Some(f) => format!(
                "the feed that fits is {:.0} % of the planned one: slow the feed (and a servo's spindle) to it, state the control's real `buffer` if it holds more, or use a faster link",
                (f * 100.0).floor()
            ),
            None => "no feed fits: a block there is longer than the buffer; state the control's real `buffer` or use a faster link".to_string(),
        }),
    )
}

/// Seconds to a tenth, or milliseconds below a second.
fn seconds_text(s: f64) -> String {
    if s >= 1.0 {
        format!(
            "{} s",
            lensc_lang::check::trim_num((s * 10.0).round() / 10.0)
        )
    } else {
        format!(
            "{} ms",
            lensc_lang::check::trim_num((s * 1e4).round() / 10.0)
        )
    }
}

/// Bytes in kB or MB, three significant figures.
fn bytes_text(b: f64) -> String {
    if b >= 1e6 {
        format!("{:.3} MB", b / 1e6)
    } else if b >= 1e3 {
        format!("{:.3} kB", b / 1e3)
    } else {
        format!("{b:.0} bytes")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(bytes: u32, seconds: f64, rapid: bool) -> LineTime {
        LineTime {
            bytes,
            seconds,
            rapid,
            feed: !rapid && seconds > 0.0,
        }
    }

    /// A cut of 100 blocks of 40 bytes, 0.1 s each (400 bytes a second),
    /// then 100 of 40 bytes, 0.01 s each (4 kB a second), fed at 1 kB a
    /// second: the average (8 kB over 11 s, 727 bytes a second) fits; the
    /// short blocks empty a 1 kB buffer mid-cut, not a 64 kB one; run at
    /// a quarter of the feed, they fit.
    #[test]
    fn a_stretch_of_short_blocks_empties_the_buffer_on_the_part() {
        let mut lines = vec![line(30, 0.0, true)];
        lines.extend((0..100).map(|_| line(40, 0.1, false)));
        lines.extend((0..100).map(|_| line(40, 0.01, false)));
        lines.push(line(30, 0.0, true));
        let s = starved(&lines, 1000.0, 1000.0, 1.0).expect("starved");
        assert!(s.first >= 101 && s.last > s.first && s.last <= 200, "{s:?}");
        let rate = s.bytes as f64 / s.seconds;
        assert!(rate > 3000.0, "{rate} bytes a second");
        assert_eq!(starved(&lines, 1000.0, 64_000.0, 1.0), None);
        assert_eq!(starved(&lines, 1000.0, 1000.0, 4.0), None);
        // A wait in the air costs nothing: cuts of two short blocks, each
        // after a retract (110 bytes, within a 120-byte buffer), at 5.5 kB
        // a second on average.
        let air: Vec<LineTime> = (0..200)
            .flat_map(|_| {
                [
                    line(30, 0.0, true),
                    line(40, 0.01, false),
                    line(40, 0.01, false),
                ]
            })
            .collect();
        assert_eq!(starved(&air, 1000.0, 120.0, 1.0), None);
        // Three blocks a cut do not fit: the control waits on the part.
        let longer: Vec<LineTime> = (0..200)
            .flat_map(|_| {
                [
                    line(30, 0.0, true),
                    line(40, 0.01, false),
                    line(40, 0.01, false),
                    line(40, 0.01, false),
                ]
            })
            .collect();
        assert!(starved(&longer, 1000.0, 120.0, 1.0).is_some());
    }
}
