//! Moves the zygote's program code onto transparent huge pages before it forks the agents.
//!
//! Why: a forked agent does not inherit the page-table entries of the program's code (the kernel copies only
//! those of memory that was written), so each agent faulted in the 2.3 MB of code it touches, 64 kB at a time, and
//! at exit took those 580-odd entries down again, one shared page at a time. At 1,000 robots that was about 0.14 s
//! of CPU before the first tick and 0.16 s after the last one (`perf record -a`; BENCHMARKS.md, "Shut-down").
//! A copy of the code on anonymous huge pages is inherited by `fork` as one entry per 2 MiB: the agents start
//! with their code mapped, and drop it with two entries at exit.
//!
//! How: the program is linked with its segments aligned to 2 MiB (`robot-agent/build.rs`), so its code starts
//! on a huge-page boundary and the space up to the next segment is free. The zygote copies the code into a
//! fresh 2 MiB-aligned anonymous mapping marked `MADV_HUGEPAGE`, makes it read-only and executable, and moves it
//! over the original with `mremap`. The copy is byte for byte the code that is running, and the zygote has one
//! thread, so nothing executes the code while it is replaced. Profilers then see the agents' code as anonymous
//! memory; `SWARM_AGENT_SMALL_PAGES=1` in the zygote's environment keeps the file mapping for profiling.

use std::io;

use nix::libc;

/// A transparent huge page.
const HUGE: usize = 2 << 20;

/// Why the code stays where it is, or how much moved onto huge pages.
#[derive(Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Bytes of code now on huge pages.
    Moved(usize),
    /// The code is not where huge pages fit (not linked with 2 MiB segments, or too small).
    DoesNotFit,
    /// Kept on the file's pages by request.
    Kept,
}

/// Moves this process's code onto huge pages; see the module documentation.
///
/// # Safety
/// The process must have one thread: the code is replaced under the running program.
pub unsafe fn move_code_to_huge_pages() -> io::Result<Outcome> {
    if std::env::var_os("SWARM_AGENT_SMALL_PAGES").is_some_and(|v| v == "1") {
        return Ok(Outcome::Kept);
    }
    let maps = std::fs::read_to_string("/proc/self/maps")?;
    let exe = std::fs::read_link("/proc/self/exe")?;
    let Some(region) = code_region(&maps, &exe.to_string_lossy()) else {
        return Ok(Outcome::DoesNotFit);
    };
    // SAFETY: `region` is this program's code mapping, which the maps show is followed by free address space up
    // to `region.start + region.len`; the caller vouches for the one thread.
    unsafe { replace_with_huge_copy(region) }?;
    Ok(Outcome::Moved(region.code_len))
}

/// The program's code mapping, rounded up to whole huge pages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Region {
    start: usize,
    /// Bytes of code (the file mapping's length).
    code_len: usize,
    /// Bytes of the huge-page mapping that replaces it.
    len: usize,
}

/// Finds `exe`'s executable mapping in `maps` (the text of `/proc/self/maps`) if it starts on a huge-page
/// boundary and nothing is mapped between its end and the next huge-page boundary.
fn code_region(maps: &str, exe: &str) -> Option<Region> {
    let ranges: Vec<(usize, usize, &str, &str)> = maps
        .lines()
        .filter_map(|line| {
            let mut fields = line.split_whitespace();
            let (start, end) = fields.next()?.split_once('-')?;
            let perms = fields.next()?;
            let path = fields.nth(3).unwrap_or("");
            Some((
                usize::from_str_radix(start, 16).ok()?,
                usize::from_str_radix(end, 16).ok()?,
                perms,
                path,
            ))
        })
        .collect();
    let &(start, end, _, _) = ranges
        .iter()
        .find(|(_, _, perms, path)| perms.starts_with("r-x") && *path == exe)?;
    let rounded_end = end.div_ceil(HUGE) * HUGE;
    let free_after = ranges
        .iter()
        .all(|&(s, e, _, _)| (s, e) == (start, end) || e <= start || s >= rounded_end);
    (start.is_multiple_of(HUGE) && free_after).then_some(Region {
        start,
        code_len: end - start,
        len: rounded_end - start,
    })
}

/// Copies the code of `region` onto fresh huge pages and moves them over it.
///
/// # Safety
/// `region` must be this program's code mapping with free address space after it up to `region.len`, and no
/// other thread may run.
unsafe fn replace_with_huge_copy(region: Region) -> io::Result<()> {
    let check = |result: libc::c_int| {
        if result == 0 {
            Ok(())
        } else {
            Err(io::Error::last_os_error())
        }
    };
    // SAFETY (all calls below): plain system calls on a mapping made here, then one mremap onto `region`,
    // which the caller vouches for.
    unsafe {
        let reserved = libc::mmap(
            std::ptr::null_mut(),
            region.len + HUGE,
            libc::PROT_READ | libc::PROT_WRITE,
            libc::MAP_PRIVATE | libc::MAP_ANONYMOUS,
            -1,
            0,
        );
        if reserved == libc::MAP_FAILED {
            return Err(io::Error::last_os_error());
        }
        let base = reserved as usize;
        let copy = base.div_ceil(HUGE) * HUGE;
        // Give back the parts of the reservation before and after the aligned copy.
        if copy > base {
            check(libc::munmap(reserved, copy - base))?;
        }
        let tail = copy + region.len;
        if base + region.len + HUGE > tail {
            check(libc::munmap(
                tail as *mut libc::c_void,
                base + region.len + HUGE - tail,
            ))?;
        }
        let copy_ptr = copy as *mut libc::c_void;
        let moved = check(libc::madvise(copy_ptr, region.len, libc::MADV_HUGEPAGE))
            .and_then(|()| {
                std::ptr::copy_nonoverlapping(
                    region.start as *const u8,
                    copy as *mut u8,
                    region.code_len,
                );
                check(libc::mprotect(
                    copy_ptr,
                    region.len,
                    libc::PROT_READ | libc::PROT_EXEC,
                ))
            })
            .and_then(|()| {
                let moved = libc::mremap(
                    copy_ptr,
                    region.len,
                    region.len,
                    libc::MREMAP_MAYMOVE | libc::MREMAP_FIXED,
                    region.start as *mut libc::c_void,
                );
                if moved == libc::MAP_FAILED {
                    Err(io::Error::last_os_error())
                } else {
                    Ok(())
                }
            });
        if moved.is_err() {
            libc::munmap(copy_ptr, region.len);
        }
        moved
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const EXE: &str = "/bin/robot-agent";

    fn maps(code: &str, next: &str) -> String {
        format!(
            "55a000000000-55a000200000 r--p 00000000 08:01 1 {EXE}\n\
             {code} r-xp 00200000 08:01 1 {EXE}\n\
             {next} r--p 00600000 08:01 1 {EXE}\n\
             7ff000000000-7ff000100000 r-xp 00000000 08:01 2 /usr/lib/libc.so.6\n"
        )
    }

    #[test]
    fn code_on_a_huge_page_boundary_with_room_after_it_is_rounded_up_to_huge_pages() {
        let text = maps("55a000200000-55a000510000", "55a000600000-55a000700000");
        assert_eq!(
            code_region(&text, EXE),
            Some(Region {
                start: 0x55a0_0020_0000,
                code_len: 0x31_0000,
                len: 0x40_0000,
            })
        );
    }

    #[test]
    fn the_copy_takes_the_place_of_the_mapping_with_its_bytes_read_only_and_executable() {
        const CODE: usize = 3 << 20;
        // A stand-in for the code: 3 MiB of known bytes on a huge-page boundary with 1 MiB free after it, carved
        // out of a reservation that stays ours (so no other thread of the test can map anything there).
        let whole = 8 << 20;
        // SAFETY: mappings made, changed and removed here only.
        let (reserved, start) = unsafe {
            let reserved = libc::mmap(
                std::ptr::null_mut(),
                whole,
                libc::PROT_NONE,
                libc::MAP_PRIVATE | libc::MAP_ANONYMOUS,
                -1,
                0,
            );
            assert_ne!(reserved, libc::MAP_FAILED);
            let start = (reserved as usize).div_ceil(HUGE) * HUGE;
            let code = libc::mmap(
                start as *mut libc::c_void,
                CODE,
                libc::PROT_READ | libc::PROT_WRITE,
                libc::MAP_PRIVATE | libc::MAP_ANONYMOUS | libc::MAP_FIXED,
                -1,
                0,
            );
            assert_eq!(code as usize, start);
            let bytes = std::slice::from_raw_parts_mut(start as *mut u8, CODE);
            for (i, byte) in bytes.iter_mut().enumerate() {
                *byte = (i % 251) as u8;
            }
            assert_eq!(libc::mprotect(code, CODE, libc::PROT_READ), 0);
            assert_eq!(
                libc::munmap((start + CODE) as *mut libc::c_void, HUGE - (CODE % HUGE)),
                0
            );
            let region = Region {
                start,
                code_len: CODE,
                len: 2 * HUGE,
            };
            replace_with_huge_copy(region).expect("the copy is moved into place");
            let bytes = std::slice::from_raw_parts(start as *const u8, CODE);
            assert!(bytes.iter().enumerate().all(|(i, &b)| b == (i % 251) as u8));
            (reserved, start)
        };
        let maps = std::fs::read_to_string("/proc/self/maps").expect("the maps");
        let line = maps
            .lines()
            .find(|line| line.starts_with(&format!("{start:x}-")))
            .expect("a mapping at the start");
        let end = start + 2 * HUGE;
        assert!(
            line.starts_with(&format!("{start:x}-{end:x} r-xp")),
            "{line}"
        );
        // SAFETY: the test's own reservation, which holds the copy.
        unsafe { libc::munmap(reserved, whole) };
    }

    #[test]
    fn code_that_is_not_aligned_or_has_no_room_after_it_stays() {
        let unaligned = maps("55a000201000-55a000510000", "55a000600000-55a000700000");
        assert_eq!(code_region(&unaligned, EXE), None);
        let crowded = maps("55a000200000-55a000510000", "55a000510000-55a000700000");
        assert_eq!(code_region(&crowded, EXE), None);
        assert_eq!(code_region(&unaligned, "/bin/other"), None);
    }
}
