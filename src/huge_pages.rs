//! Transparent huge pages for the heap, on Linux with glibc: the binary runs itself again with
//! glibc's `glibc.malloc.hugetlb=1` tunable, so that its large arrays are backed by 2 MiB
//! pages where the kernel gives them only to memory marked for them (`madvise` mode, the usual
//! default). A million balls' arrays are about 300 MB, which 4 KiB pages map with 75,000 entries
//! against the processor's few thousand: most of a step's scattered reads then also walk
//! the page tables. Measured (docs/performance.md, *Huge pages for the heap*): a million balls
//! 4–6% faster a step, peak memory 3–6 MiB higher.
//!
//! Called first thing in `main`, before anything else has run. A tunable can only be set
//! before a process starts, and setting it from safe code means starting the process again.
//! Nothing here changes a result. Each new process is told which start it is
//! ([`RESTARTED`]), since glibc drops `GLIBC_TUNABLES` for a program that runs with raised
//! privileges; it starts once more only if glibc let the tunable go by, which glibc 2.35 and
//! 2.36 do in about half the starts, at random (`glibc_took_huge_pages`), and at most
//! [`MOST_STARTS`] starts in all. The user's own choice wins: a `GLIBC_TUNABLES` that names
//! `glibc.malloc.hugetlb` (`=0` turns it off, `=1` asks for the pages without a second start)
//! or that glibc would not read as it is is left alone. It does not start again under valgrind
//! either, which follows a new program only when told to (`--trace-children=yes`), so the run
//! would escape it and callgrind's counts with it; nor when the binary was started through
//! the dynamic loader (`ld-linux-x86-64.so.2 ballpit ...`), whose path it would take for its
//! own. If the start fails, it runs on as it is.

use std::ffi::{OsStr, OsString};

/// The environment variable glibc reads its tunables from, `name=value` pairs joined by `:`.
pub const TUNABLES: &str = "GLIBC_TUNABLES";

/// Set in the environment of each start made here, to its number (2 for the first made here),
/// so that the starts end.
pub const RESTARTED: &str = "BALLPIT_RESTARTED_FOR_HUGE_PAGES";

/// The tunable that makes glibc's `malloc` mark its memory for transparent huge pages.
const HUGE_PAGES: &str = "glibc.malloc.hugetlb";

/// `GLIBC_TUNABLES` with huge pages asked for, given its value now; `None` to leave it alone:
/// it already names the huge-pages tunable (asked for, or turned off by the user), cannot be
/// read as text, or is not a list of `name=value` pairs joined by `:` as glibc reads it.
pub fn tunables_with_huge_pages(current: Option<&OsStr>) -> Option<OsString> {
    let asked = format!("{HUGE_PAGES}=1");
    let Some(current) = current.filter(|current| !current.is_empty()) else {
        return Some(asked.into());
    };
    let current = current.to_str()?;
    let pairs: Vec<(&str, &str)> = current
        .split(':')
        .map(|pair| pair.split_once('='))
        .collect::<Option<_>>()?;
    let well_formed = pairs
        .iter()
        .all(|(name, value)| !name.is_empty() && !value.contains('='));
    let named = pairs.iter().any(|&(name, _)| name == HUGE_PAGES);
    (well_formed && !named).then(|| format!("{current}:{asked}").into())
}

/// The start to make, as its `GLIBC_TUNABLES` and its number ([`RESTARTED`]), given the
/// environment's [`RESTARTED`], `LD_PRELOAD` and `GLIBC_TUNABLES`; `None` to run on. A start
/// made here starts once more only if `missed_the_pages()` (asked only there), with the
/// tunables it was given, while its number allows ([`next_start`]); the first start, unless
/// valgrind runs it or the tunables are to be left alone ([`tunables_with_huge_pages`]).
pub fn start_to_make(
    restarted: Option<&OsStr>,
    preloaded: Option<&OsStr>,
    tunables: Option<&OsStr>,
    missed_the_pages: impl FnOnce() -> bool,
) -> Option<(OsString, u32)> {
    match restarted {
        Some(restarted) => {
            let start = next_start(restarted)?;
            let tunables = tunables?.to_owned();
            missed_the_pages().then_some((tunables, start))
        }
        None if under_valgrind(preloaded) => None,
        None => Some((tunables_with_huge_pages(tunables)?, 2)),
    }
}

/// Whether the preloaded libraries (`LD_PRELOAD`) are valgrind's, which it gives every
/// program it runs (`vgpreload_core-amd64-linux.so` and the tool's own).
pub fn under_valgrind(preloaded: Option<&OsStr>) -> bool {
    preloaded.is_some_and(|preloaded| preloaded.to_string_lossy().contains("vgpreload"))
}

/// Whether `binary`, the running program's file, is the dynamic loader (`ld-linux-*.so.*`),
/// as it is when the loader was asked to run the binary: starting it again would run the
/// loader with the binary's arguments.
pub fn is_the_loader(binary: &std::path::Path) -> bool {
    binary
        .file_name()
        .is_some_and(|name| name.to_string_lossy().starts_with("ld-"))
}

/// Starts this binary again, with the same arguments, with huge pages asked for (see the
/// header). Returns at once if the pages are already asked for or refused, under valgrind
/// or the loader, and if the start failed. A start that asked for them returns unless glibc
/// let them go by (`glibc_took_huge_pages`), where it starts once more, up to
/// [`MOST_STARTS`] starts in all.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
pub fn rerun_with_huge_pages() {
    use std::os::unix::process::CommandExt;
    use std::process::Command;

    let env = std::env::var_os;
    let (restarted, preloaded, tunables) = (env(RESTARTED), env("LD_PRELOAD"), env(TUNABLES));
    let missed_the_pages = || kernel_gives_huge_pages_when_asked() && !glibc_took_huge_pages();
    let Some((tunables, start)) = start_to_make(
        restarted.as_deref(),
        preloaded.as_deref(),
        tunables.as_deref(),
        missed_the_pages,
    ) else {
        return;
    };
    let Ok(binary) = std::env::current_exe() else {
        return;
    };
    if is_the_loader(&binary) {
        return;
    }
    let mut args = std::env::args_os();
    let mut command = Command::new(binary);
    if let Some(name) = args.next() {
        command.arg0(name);
    }
    command
        .args(args)
        .env(TUNABLES, tunables)
        .env(RESTARTED, start.to_string());
    // `exec` replaces this process and returns only on failure: then run on without.
    let _failed = command.exec();
}

/// The most starts [`rerun_with_huge_pages`] makes, the first included: glibc lets the pages
/// go by in about half of them (see `glibc_took_huge_pages`), so all seven miss about once
/// in a hundred runs.
pub const MOST_STARTS: u32 = 7;

/// The number of the start after the one whose [`RESTARTED`] is `restarted` (the first start
/// is 1, the second, the first made here, 2), or `None` if it would pass [`MOST_STARTS`] or
/// `restarted` is no number.
pub fn next_start(restarted: &OsStr) -> Option<u32> {
    let start: u32 = restarted.to_str()?.parse().ok()?;
    let start = start.max(1);
    (start < MOST_STARTS).then_some(start + 1)
}

/// Whether the kernel gives transparent huge pages to memory marked for them and only to it
/// (`madvise` mode), the mode in which the tunable matters.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn kernel_gives_huge_pages_when_asked() -> bool {
    std::fs::read_to_string("/sys/kernel/mm/transparent_hugepage/enabled")
        .is_ok_and(|mode| mode.contains("[madvise]"))
}

/// Whether this process's `malloc` marks its large blocks for huge pages, as the tunable asks.
/// glibc 2.35 and 2.36 read the kernel's mode into a buffer and compare it as a string
/// without ending it (later releases end it: `str[s] = '\0'` in `malloc-hugepages.c`), so
/// whether they see `madvise` depends on the byte that follows on the stack, which moves
/// with the address space's random layout and the program's path and arguments: in about
/// half the starts they let the tunable go by (on this project's machine, 3 of 6 runs of
/// 1,000,000 balls and 5 of 12 of 300,000). So a block of [`PROBE_BYTES`], which `malloc`
/// maps on its own, is looked up in `/proc/self/smaps`: marked, it may have huge pages
/// (`THPeligible: 1`). If the file cannot be read, the answer is yes: run on.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn glibc_took_huge_pages() -> bool {
    let probe = vec![0_u8; PROBE_BYTES];
    let address = std::hint::black_box(probe.as_ptr()) as usize;
    std::fs::read_to_string("/proc/self/smaps")
        .ok()
        .and_then(|smaps| huge_pages_allowed_at(&smaps, address))
        .unwrap_or(true)
}

/// A block this large is mapped on its own by glibc's `malloc` (over its threshold of 128 KiB
/// at the start) and is at least one huge page (2 MiB), so the tunable marks it.
pub const PROBE_BYTES: usize = 4 << 20;

/// What the mapping holding `address` in `smaps` (the text of `/proc/PID/smaps`) says of
/// huge pages (`THPeligible`), or `None` if no mapping holds it or it does not say.
pub fn huge_pages_allowed_at(smaps: &str, address: usize) -> Option<bool> {
    let mut holds = false;
    for line in smaps.lines() {
        if let Some(range) = mapping_range(line) {
            holds = range.contains(&address);
        } else if let Some(value) = line.strip_prefix("THPeligible:").filter(|_| holds) {
            return Some(value.trim() == "1");
        }
    }
    None
}

/// The addresses of the mapping whose first line in `smaps` is `line`
/// (`7f3a1c000000-7f3a1c401000 rw-p ...`), or `None` for a line of its fields.
fn mapping_range(line: &str) -> Option<std::ops::Range<usize>> {
    let (range, _) = line.split_once(' ')?;
    let (start, end) = range.split_once('-')?;
    let hex = |text: &str| usize::from_str_radix(text, 16).ok();
    Some(hex(start)?..hex(end)?)
}

/// Elsewhere there is no such tunable: nothing to do.
#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
pub fn rerun_with_huge_pages() {}

#[cfg(test)]
mod tests {
    use super::*;

    fn with(current: Option<&str>) -> Option<String> {
        tunables_with_huge_pages(current.map(OsStr::new)).map(|value| value.into_string().unwrap())
    }

    #[test]
    fn huge_pages_are_asked_for_unless_the_user_named_them() {
        let asked = Some("glibc.malloc.hugetlb=1".to_string());
        assert_eq!(with(None), asked);
        assert_eq!(with(Some("")), asked);
        // Other tunables are kept, in their order, with ours after them.
        assert_eq!(
            with(Some("glibc.malloc.arena_max=2:glibc.malloc.tcache_count=0")).as_deref(),
            Some("glibc.malloc.arena_max=2:glibc.malloc.tcache_count=0:glibc.malloc.hugetlb=1")
        );
        // Already asked for (by an earlier start), or turned off: left alone, so no loop.
        assert_eq!(with(Some("glibc.malloc.hugetlb=1")), None);
        assert_eq!(
            with(Some("glibc.malloc.arena_max=2:glibc.malloc.hugetlb=0")),
            None
        );
        // A name that only begins like ours is another tunable.
        assert_eq!(
            with(Some("glibc.malloc.hugetlbx=1")).as_deref(),
            Some("glibc.malloc.hugetlbx=1:glibc.malloc.hugetlb=1")
        );
    }

    #[test]
    fn it_starts_again_until_glibc_takes_the_pages_and_never_under_valgrind() {
        let os = |value: &'static str| Some(OsStr::new(value));
        let asked = OsString::from("glibc.malloc.hugetlb=1");
        // The first start is decided without looking for the pages.
        let first = |preloaded, tunables| {
            start_to_make(None, preloaded, tunables, || unreachable!("no probe"))
        };
        assert_eq!(first(None, None), Some((asked.clone(), 2)));
        assert_eq!(first(os("libfoo.so"), None), Some((asked.clone(), 2)));
        let valgrind = os("/usr/libexec/valgrind/vgpreload_core-amd64-linux.so");
        assert_eq!(first(valgrind, None), None);
        // The user's own choice.
        assert_eq!(first(None, os("glibc.malloc.hugetlb=0")), None);
        // A start made here that has the pages runs on; one that missed them starts once
        // more with the same tunables, up to the last start.
        let made = |restarted, missed| start_to_make(os(restarted), None, os("x=1"), || missed);
        assert_eq!(made("2", false), None);
        assert_eq!(made("2", true), Some((OsString::from("x=1"), 3)));
        assert_eq!(made("1", true), Some((OsString::from("x=1"), 2)));
        assert_eq!(made("7", true), None);
        // Where glibc dropped the tunable it was given, nothing to start with.
        assert_eq!(start_to_make(os("2"), None, None, || true), None);
        assert_eq!(start_to_make(os("1"), None, None, || false), None);
    }

    #[test]
    fn a_list_glibc_would_not_read_as_it_is_is_left_alone() {
        // glibc skips or rejects parts of these, or the whole; appending could change what
        // it reads, so they stay as the user wrote them.
        for odd in [
            "glibc.malloc.arena_max=2:",
            "glibc.malloc.arena_max=2::glibc.malloc.tcache_count=0",
            "glibc.malloc.hugetlb",
            "glibc.malloc.arena_max",
            "=2",
            "glibc.malloc.arena_max=2=3",
        ] {
            assert_eq!(with(Some(odd)), None, "{odd}");
        }
    }

    #[test]
    fn the_starts_are_numbered_and_end() {
        let next = |restarted: &str| next_start(OsStr::new(restarted));
        assert_eq!(next("2"), Some(3));
        // An earlier build numbered its one start made here 1.
        assert_eq!(next("1"), Some(2));
        assert_eq!(next("0"), Some(2));
        assert_eq!(next(&(MOST_STARTS - 1).to_string()), Some(MOST_STARTS));
        assert_eq!(next(&MOST_STARTS.to_string()), None);
        assert_eq!(next("4000000000"), None);
        assert_eq!(next("yes"), None);
        assert_eq!(next(""), None);
    }

    #[test]
    fn the_mapping_holding_an_address_says_whether_it_may_have_huge_pages() {
        let smaps = "\
55d0c0a00000-55d0c0a21000 rw-p 00000000 00:00 0                          [heap]
Size:                132 kB
THPeligible:    0
7f3a1c000000-7f3a1c401000 rw-p 00000000 00:00 0
Size:               4100 kB
AnonHugePages:      2048 kB
THPeligible:    1
VmFlags: rd wr mr mw me ac sd hg
7f3a1d000000-7f3a1d001000 r--p 00000000 08:01 1234                       /usr/lib/libc.so.6
Size:                  4 kB
";
        let allowed = |address: usize| huge_pages_allowed_at(smaps, address);
        assert_eq!(allowed(0x7f3a_1c00_0000), Some(true));
        assert_eq!(allowed(0x7f3a_1c40_0fff), Some(true));
        assert_eq!(allowed(0x55d0_c0a0_0010), Some(false));
        // Past the end of a mapping, in one that does not say, or in none.
        assert_eq!(allowed(0x7f3a_1c40_1000), None);
        assert_eq!(allowed(0x7f3a_1d00_0000), None);
        assert_eq!(allowed(0x1000), None);
        assert_eq!(huge_pages_allowed_at("", 0x1000), None);
    }

    #[test]
    fn the_loader_is_not_taken_for_the_binary() {
        use std::path::Path;
        assert!(is_the_loader(Path::new("/lib64/ld-linux-x86-64.so.2")));
        assert!(is_the_loader(Path::new(
            "/usr/lib/x86_64-linux-gnu/ld-2.36.so"
        )));
        assert!(!is_the_loader(Path::new(
            "/work/main/target/release/ballpit"
        )));
        assert!(!is_the_loader(Path::new("/opt/ballpit/bin/ballpit-ld")));
    }

    #[test]
    fn valgrind_is_known_by_its_preloaded_libraries() {
        let preloaded = |value: &str| under_valgrind(Some(OsStr::new(value)));
        assert!(preloaded(
            "/usr/libexec/valgrind/vgpreload_core-amd64-linux.so:\
             /usr/libexec/valgrind/vgpreload_memcheck-amd64-linux.so"
        ));
        assert!(!preloaded("/usr/lib/x86_64-linux-gnu/libjemalloc.so.2"));
        assert!(!preloaded(""));
        assert!(!under_valgrind(None));
    }

    #[cfg(unix)]
    #[test]
    fn a_value_that_is_not_text_is_left_alone() {
        use std::os::unix::ffi::OsStrExt;
        assert_eq!(
            tunables_with_huge_pages(Some(OsStr::from_bytes(b"\xff=1"))),
            None
        );
    }
}
