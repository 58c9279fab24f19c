//! Keeps the bridge's UDP sockets to traffic from this machine.
//!
//! RustDDS 0.15 binds every socket of a participant to the wildcard address (0.0.0.0; the
//! address is hard-coded in its participant), so a datagram sent to this machine from
//! elsewhere would reach them even though the bridge advertises only loopback locators.
//! Each socket gets a classic BPF socket filter (socket(7) `SO_ATTACH_FILTER`, no privilege
//! needed) that takes a datagram only if it came in through the loopback device; the kernel
//! drops every other one before the DDS stack sees it, and counts it in the socket's drops
//! (/proc/net/udp).
//!
//! Why a filter and not `SO_BINDTODEVICE lo`: traffic between processes of this machine
//! always comes in through the loopback device, also when it is addressed to the machine's
//! LAN address, but a socket bound to `lo` also sends through `lo` and its datagrams then
//! arrive with `lo` as their interface. Cyclone DDS drops discovery packets that arrive on
//! an interface it did not select, and rmw_cyclonedds in ROS 2 Jazzy's LOCALHOST discovery
//! range selects the LAN interface and reaches peers at the LAN address: such a node then
//! never heard the bridge. The filter leaves sending alone; the bridge advertises only
//! loopback locators and sends multicast only on loopback, so it only ever answers peers
//! it heard, and it hears only this machine.
//!
//! The participant's sockets are the internet datagram sockets that appear in this process
//! while it is built: RustDDS's `build()` returns only after its event loop has made its
//! sender sockets, and readers and writers made later share them. A filter applies to what
//! arrives after it is attached: a datagram from elsewhere in the few milliseconds between
//! the socket's creation and the filter would still be read.

use agrisim_error::{err, Result};
use socket2::{Domain, SockFilter, SockRef, Type};
use std::collections::BTreeSet;
use std::os::fd::{BorrowedFd, RawFd};

/// An open socket of this process: its descriptor and its inode (the pair tells a socket
/// made anew from an old one whose descriptor number was reused).
type Open = (RawFd, u64);

/// This process's internet (IPv4 or IPv6) datagram sockets.
pub fn udp_sockets() -> Result<BTreeSet<Open>> {
    let dir = std::fs::read_dir("/proc/self/fd").map_err(|e| err!("ROS 2 bridge: cannot list /proc/self/fd: {e}"))?;
    let mut found = BTreeSet::new();
    for entry in dir.flatten() {
        let Some(fd) = entry.file_name().to_str().and_then(|n| n.parse::<RawFd>().ok()) else { continue };
        // The descriptor may close while we look (the listing's own one does): skip it.
        let Ok(target) = std::fs::read_link(entry.path()) else { continue };
        let Some(inode) = socket_inode(&target.to_string_lossy()) else { continue };
        // SAFETY: the descriptor was open a moment ago and is only borrowed for two queries;
        // if it closed meanwhile the queries fail with EBADF and the socket is skipped.
        let borrowed = unsafe { BorrowedFd::borrow_raw(fd) };
        let sock = SockRef::from(&borrowed);
        let inet = matches!(sock.domain(), Ok(d) if d == Domain::IPV4 || d == Domain::IPV6);
        if inet && matches!(sock.r#type(), Ok(t) if t == Type::DGRAM) {
            found.insert((fd, inode));
        }
    }
    Ok(found)
}

/// `socket:[12345]` -> 12345 (the form of a socket's link in /proc/PID/fd).
fn socket_inode(link: &str) -> Option<u64> {
    link.strip_prefix("socket:[")?.strip_suffix(']')?.parse().ok()
}

/// The loopback device's interface index (1 in every network namespace of today's kernels;
/// read, not assumed).
fn loopback_index() -> Result<u32> {
    let path = "/sys/class/net/lo/ifindex";
    let text = std::fs::read_to_string(path).map_err(|e| err!("ROS 2 bridge: cannot read {path}: {e}"))?;
    text.trim().parse().map_err(|e| err!("ROS 2 bridge: {path}: '{}': {e}", text.trim()))
}

/// The filter program: accept a datagram whole if the device it came in through is
/// `lo_index`, else drop it (classic BPF, linux/filter.h).
fn loopback_only(lo_index: u32) -> [SockFilter; 4] {
    const LD_W_ABS: u16 = 0x20; // BPF_LD | BPF_W | BPF_ABS
    const JEQ_K: u16 = 0x15; // BPF_JMP | BPF_JEQ | BPF_K
    const RET_K: u16 = 0x06; // BPF_RET | BPF_K
                             // The ancillary load SKF_AD_OFF + SKF_AD_IFINDEX: the receiving device's index.
    const IFINDEX: u32 = (-0x1000i32 + 8) as u32;
    [
        SockFilter::new(LD_W_ABS, 0, 0, IFINDEX),
        SockFilter::new(JEQ_K, 0, 1, lo_index),
        SockFilter::new(RET_K, 0, 0, u32::MAX),
        SockFilter::new(RET_K, 0, 0, 0),
    ]
}

/// Filters every internet datagram socket opened since `before` was taken to datagrams that
/// came in through the loopback device. Returns how many it filtered; none is an error (the
/// participant would be listening somewhere this code cannot see).
pub fn confine_new(before: &BTreeSet<Open>) -> Result<usize> {
    let new: Vec<Open> = udp_sockets()?.difference(before).copied().collect();
    if new.is_empty() {
        return Err(err!("ROS 2 bridge: found no new UDP socket of the DDS participant to keep to this machine"));
    }
    let program = loopback_only(loopback_index()?);
    for &(fd, _) in &new {
        // SAFETY: the participant owns the socket and keeps it open while it lives; it is
        // only borrowed here, for one option.
        let borrowed = unsafe { BorrowedFd::borrow_raw(fd) };
        let sock = SockRef::from(&borrowed);
        let local = sock.local_addr().ok().and_then(|a| a.as_socket()).map_or("?".to_string(), |a| a.to_string());
        sock.attach_filter(&program).map_err(|e| {
            err!("ROS 2 bridge: cannot filter the DDS socket {local} to traffic from this machine (SO_ATTACH_FILTER: {e}); --ros2-all-interfaces talks on every interface instead")
        })?;
    }
    Ok(new.len())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::net::UdpSocket;
    use std::os::fd::AsRawFd;
    use std::time::Duration;

    /// Instructions in the socket's filter (0: none), by SO_GET_FILTER with no buffer.
    fn filter_len(s: &UdpSocket) -> u32 {
        let mut len: libc::socklen_t = 0;
        let r = unsafe {
            libc::getsockopt(s.as_raw_fd(), libc::SOL_SOCKET, libc::SO_ATTACH_FILTER, std::ptr::null_mut(), &mut len)
        };
        assert_eq!(r, 0, "{}", std::io::Error::last_os_error());
        len
    }

    #[test]
    fn reads_a_socket_link() {
        assert_eq!(socket_inode("socket:[4026532]"), Some(4026532));
        assert_eq!(socket_inode("pipe:[4026532]"), None);
        assert_eq!(socket_inode("/dev/null"), None);
    }

    #[test]
    fn filters_exactly_the_sockets_opened_since() {
        let _serial = crate::SOCKET_TESTS.lock().unwrap_or_else(|e| e.into_inner());
        let old = UdpSocket::bind("0.0.0.0:0").unwrap();
        let before = udp_sockets().unwrap();
        assert!(before.iter().any(|&(fd, _)| fd == old.as_raw_fd()));
        let tcp = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let new = UdpSocket::bind("0.0.0.0:0").unwrap();
        assert_eq!(confine_new(&before).unwrap(), 1, "only the new UDP socket, not the TCP one nor the old one");
        assert_eq!(filter_len(&new), 4);
        assert_eq!(filter_len(&old), 0);
        drop(tcp);
        // Traffic from this machine still arrives, to the loopback address and to any other
        // address of the machine (it comes in through the loopback device either way).
        let tx = UdpSocket::bind("0.0.0.0:0").unwrap();
        new.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
        let port = new.local_addr().unwrap().port();
        let mut buf = [0u8; 4];
        tx.send_to(b"hi", ("127.0.0.1", port)).unwrap();
        assert_eq!(new.recv(&mut buf).unwrap(), 2);
        tx.send_to(b"ho", ("127.0.0.2", port)).unwrap();
        assert_eq!(new.recv(&mut buf).unwrap(), 2);
        // Nothing new since: an error, not a silent success.
        assert!(confine_new(&udp_sockets().unwrap()).is_err());
    }

    #[test]
    fn the_loopback_device_is_found() {
        assert!(loopback_index().unwrap() >= 1);
    }
}
