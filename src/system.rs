//! What the system says about itself: the memory it can give now, and the address space the
//! process may still take.

/// The memory the system can give now (`MemAvailable`), where it says (Linux).
pub fn available_bytes() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_ascii_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// The address space the process may still take: its limit (`RLIMIT_AS`, what `ulimit -v`
/// sets) less what it has mapped now (`VmSize`). `None` where no limit is set or the system
/// does not say (Linux only). An allocation past the limit fails, and Rust aborts the
/// process on a failed allocation, so a job must fit in this before it starts
/// (docs/decisions.md, "Address space").
pub fn address_space_left() -> Option<u64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    Some(address_space_limit(&limits)?.saturating_sub(mapped_bytes(&status)?))
}

/// Under an address-space limit, keeps the C allocator to one arena (glibc's `M_ARENA_MAX`).
/// Each thread's arena reserves 64 MiB of address space that the limit counts, though the
/// memory used is far less: a 5K-vertex `match` on 2 cores peaked at 432 MiB of address
/// space for 85 MiB used, 162 MiB with one arena (docs/decisions.md, "Address space").
/// Done once per process, at the first job or C call; without a limit nothing changes.
pub fn fit_allocator_to_address_space_limit() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        #[cfg(all(target_os = "linux", target_env = "gnu"))]
        if address_space_left().is_some() {
            // SAFETY: mallopt sets a parameter of glibc's allocator, allowed at any time.
            unsafe {
                libc::mallopt(libc::M_ARENA_MAX, 1);
            }
        }
    });
}

/// The soft address-space limit of `/proc/self/limits` text, in bytes; `None` if unlimited.
fn address_space_limit(limits: &str) -> Option<u64> {
    let line = limits
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    line["Max address space".len()..]
        .split_ascii_whitespace()
        .next()?
        .parse()
        .ok()
}

/// The mapped address space (`VmSize`) of `/proc/self/status` text, in bytes.
fn mapped_bytes(status: &str) -> Option<u64> {
    let line = status.lines().find(|l| l.starts_with("VmSize:"))?;
    let kib: u64 = line.split_ascii_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn address_space_limit_is_the_soft_limit_or_none_when_unlimited() {
        let capped = "Limit                     Soft Limit           Hard Limit           Units     \n\
                      Max stack size            8388608              unlimited            bytes     \n\
                      Max address space         307200000            unlimited            bytes     \n";
        assert_eq!(address_space_limit(capped), Some(307_200_000));
        let unlimited =
            "Max address space         unlimited            unlimited            bytes     \n";
        assert_eq!(address_space_limit(unlimited), None);
        assert_eq!(address_space_limit(""), None);
    }

    #[test]
    fn mapped_bytes_reads_vmsize_in_kib() {
        let status = "Name:\tshapecorr\nVmPeak:\t  515220 kB\nVmSize:\t  490180 kB\n";
        assert_eq!(mapped_bytes(status), Some(490_180 * 1024));
        assert_eq!(mapped_bytes("Name:\tx\n"), None);
    }
}
