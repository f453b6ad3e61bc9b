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
//! Nothing here changes a result. It starts again at most once: the new process is told so
//! ([`RESTARTED`]), since glibc drops `GLIBC_TUNABLES` for a program that runs with raised
//! privileges. The user's own choice wins: a `GLIBC_TUNABLES` that names
//! `glibc.malloc.hugetlb` (`=0` turns it off, `=1` asks for the pages without a second start)
//! or that glibc would not read as it is is left alone. It does not start again under valgrind
//! either, which follows a new program only when told to (`--trace-children=yes`), so the run
//! would escape it and callgrind's counts with it; nor when the binary was started through
//! the dynamic loader (`ld-linux-x86-64.so.2 ballpit ...`), whose path it would take for its
//! own. If the start fails, it runs on as it is.

use std::ffi::{OsStr, OsString};

/// The environment variable glibc reads its tunables from, `name=value` pairs joined by `:`.
pub const TUNABLES: &str = "GLIBC_TUNABLES";

/// Set in the environment of the second start, so that it never starts a third.
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

/// The `GLIBC_TUNABLES` to start again with, given the environment's [`RESTARTED`],
/// `LD_PRELOAD` and `GLIBC_TUNABLES`; `None` not to start again: this is the second start,
/// valgrind runs it, or the tunables are to be left alone ([`tunables_with_huge_pages`]).
pub fn tunables_for_a_second_start(
    restarted: Option<&OsStr>,
    preloaded: Option<&OsStr>,
    tunables: Option<&OsStr>,
) -> Option<OsString> {
    if restarted.is_some() || under_valgrind(preloaded) {
        return None;
    }
    tunables_with_huge_pages(tunables)
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
/// header). Returns at once in the second start, if the pages are already asked for or
/// refused, under valgrind or the loader, and if the start failed.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
pub fn rerun_with_huge_pages() {
    use std::os::unix::process::CommandExt;
    use std::process::Command;

    let env = std::env::var_os;
    let (restarted, preloaded, tunables) = (env(RESTARTED), env("LD_PRELOAD"), env(TUNABLES));
    let Some(tunables) = tunables_for_a_second_start(
        restarted.as_deref(),
        preloaded.as_deref(),
        tunables.as_deref(),
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
        .env(RESTARTED, "1");
    // `exec` replaces this process and returns only on failure: then run on without.
    let _failed = command.exec();
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
    fn it_starts_again_at_most_once_and_never_under_valgrind() {
        let os = |value: &'static str| Some(OsStr::new(value));
        let asked = Some(OsString::from("glibc.malloc.hugetlb=1"));
        assert_eq!(tunables_for_a_second_start(None, None, None), asked);
        assert_eq!(
            tunables_for_a_second_start(None, os("libfoo.so"), None),
            asked
        );
        // The second start, even where glibc dropped the tunable it was given.
        assert_eq!(tunables_for_a_second_start(os("1"), None, None), None);
        let valgrind = os("/usr/libexec/valgrind/vgpreload_core-amd64-linux.so");
        assert_eq!(tunables_for_a_second_start(None, valgrind, None), None);
        // The user's own choice.
        let off = os("glibc.malloc.hugetlb=0");
        assert_eq!(tunables_for_a_second_start(None, None, off), None);
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
