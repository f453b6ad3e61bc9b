//! Transparent huge pages for the heap, on Linux with glibc: the binary runs itself again with
//! glibc's `glibc.malloc.hugetlb=1` tunable, so that its large arrays are backed by 2 MiB
//! pages where the kernel gives them only to memory marked for them (`madvise` mode, the usual
//! default). A million balls' arrays are about 300 MB, which 4 KiB pages map with 75,000 entries
//! against the processor's few thousand: most of a step's scattered reads then also walk
//! the page tables. Measured (docs/performance.md, *Huge pages for the heap*): a million balls
//! 5–7% faster a step, peak memory 3 MiB higher.
//!
//! Called first thing in `main`, before anything else has run. A tunable can only be set
//! before a process starts, and setting it from safe code means starting the process again.
//! Nothing here changes a result. The user's own choice wins: a `GLIBC_TUNABLES` that already
//! names `glibc.malloc.hugetlb` (`=0` turns it off) is left alone, and if the binary cannot be
//! started again it runs on as it is. Under valgrind it is not started again either: valgrind
//! follows a new program only when told to (`--trace-children=yes`), so the run would escape
//! it, and callgrind's counts with it.

use std::ffi::{OsStr, OsString};

/// The environment variable glibc reads its tunables from, `name=value` pairs joined by `:`.
pub const TUNABLES: &str = "GLIBC_TUNABLES";

/// The tunable that makes glibc's `malloc` mark its memory for transparent huge pages.
const HUGE_PAGES: &str = "glibc.malloc.hugetlb";

/// `GLIBC_TUNABLES` with huge pages asked for, given its value now; `None` if it already names
/// the huge-pages tunable (asked for, or turned off by the user), or cannot be read as text.
pub fn tunables_with_huge_pages(current: Option<&OsStr>) -> Option<OsString> {
    let asked = format!("{HUGE_PAGES}=1");
    let Some(current) = current.filter(|current| !current.is_empty()) else {
        return Some(asked.into());
    };
    let current = current.to_str()?;
    let named = current
        .split(':')
        .any(|pair| pair.split('=').next() == Some(HUGE_PAGES));
    (!named).then(|| format!("{current}:{asked}").into())
}

/// Whether the preloaded libraries (`LD_PRELOAD`) are valgrind's, which it gives every
/// program it runs (`vgpreload_core-amd64-linux.so` and the tool's own).
pub fn under_valgrind(preloaded: Option<&OsStr>) -> bool {
    preloaded.is_some_and(|preloaded| preloaded.to_string_lossy().contains("vgpreload"))
}

/// Starts this binary again, with the same arguments, with huge pages asked for (see the
/// header); returns only if they are already asked for or refused, under valgrind, or if the
/// start failed.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
pub fn rerun_with_huge_pages() {
    use std::os::unix::process::CommandExt;
    use std::process::Command;

    if under_valgrind(std::env::var_os("LD_PRELOAD").as_deref()) {
        return;
    }
    let Some(tunables) = tunables_with_huge_pages(std::env::var_os(TUNABLES).as_deref()) else {
        return;
    };
    let Ok(binary) = std::env::current_exe() else {
        return;
    };
    let mut args = std::env::args_os();
    let mut command = Command::new(binary);
    if let Some(name) = args.next() {
        command.arg0(name);
    }
    // `exec` replaces this process and returns only on failure: then run on without.
    let _failed = command.args(args).env(TUNABLES, tunables).exec();
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
