//! Keeps the bridge's UDP sockets on the loopback device.
//!
//! RustDDS 0.15 binds every socket of a participant to the wildcard address (0.0.0.0; the
//! address is hard-coded in its participant), so a datagram sent to this machine from
//! elsewhere would reach them even though the bridge advertises only loopback locators.
//! Linux can confine a socket bound to the wildcard to one device (`SO_BINDTODEVICE`,
//! socket(7); allowed without privileges since Linux 5.7 for a socket not yet bound to one):
//! the kernel then delivers it only datagrams that arrive on that device, and a datagram
//! from another interface finds no socket (the sender gets "port unreachable").
//!
//! The participant's sockets are the internet datagram sockets that appear in this process
//! while it is built: RustDDS's `build()` returns only after its event loop has made its
//! sender sockets, and readers and writers made later share them.

use agrisim_error::{err, Result};
use socket2::{Domain, SockRef, Type};
use std::collections::BTreeSet;
use std::os::fd::{BorrowedFd, RawFd};

/// The loopback device's name on Linux.
const LOOPBACK: &[u8] = b"lo";

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

/// Confines every internet datagram socket opened since `before` was taken to the loopback
/// device, and checks that the kernel holds each to it. Returns how many it confined; none
/// is an error (the participant would be listening somewhere this code cannot see).
pub fn confine_new(before: &BTreeSet<Open>) -> Result<usize> {
    let new: Vec<Open> = udp_sockets()?.difference(before).copied().collect();
    if new.is_empty() {
        return Err(err!("ROS 2 bridge: found no new UDP socket of the DDS participant to keep on loopback"));
    }
    for &(fd, _) in &new {
        // SAFETY: the participant owns the socket and keeps it open while it lives; it is
        // only borrowed here, for one option.
        let borrowed = unsafe { BorrowedFd::borrow_raw(fd) };
        let sock = SockRef::from(&borrowed);
        let local = sock.local_addr().ok().and_then(|a| a.as_socket()).map_or("?".to_string(), |a| a.to_string());
        sock.bind_device(Some(LOOPBACK)).map_err(|e| {
            err!("ROS 2 bridge: cannot keep the DDS socket {local} on the loopback device (SO_BINDTODEVICE: {e}; Linux 5.7 or later, or CAP_NET_RAW, is needed); --ros2-all-interfaces talks on every interface instead")
        })?;
        match sock.device() {
            Ok(Some(dev)) if dev == LOOPBACK => {}
            other => return Err(err!("ROS 2 bridge: the DDS socket {local} is not held to the loopback device after SO_BINDTODEVICE ({other:?})")),
        }
    }
    Ok(new.len())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::net::UdpSocket;
    use std::time::Duration;

    #[test]
    fn reads_a_socket_link() {
        assert_eq!(socket_inode("socket:[4026532]"), Some(4026532));
        assert_eq!(socket_inode("pipe:[4026532]"), None);
        assert_eq!(socket_inode("/dev/null"), None);
    }

    #[test]
    fn confines_exactly_the_sockets_opened_since() {
        let old = UdpSocket::bind("0.0.0.0:0").unwrap();
        let before = udp_sockets().unwrap();
        assert!(before.iter().any(|&(fd, _)| fd == std::os::fd::AsRawFd::as_raw_fd(&old)));
        let tcp = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let new = UdpSocket::bind("0.0.0.0:0").unwrap();
        assert_eq!(confine_new(&before).unwrap(), 1, "only the new UDP socket, not the TCP one nor the old one");
        assert_eq!(SockRef::from(&new).device().unwrap().as_deref(), Some(LOOPBACK));
        assert_eq!(SockRef::from(&old).device().unwrap(), None);
        drop(tcp);
        // Loopback traffic still arrives.
        let tx = UdpSocket::bind("127.0.0.1:0").unwrap();
        tx.send_to(b"hi", ("127.0.0.1", new.local_addr().unwrap().port())).unwrap();
        new.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
        let mut buf = [0u8; 4];
        assert_eq!(new.recv(&mut buf).unwrap(), 2);
        // Nothing new since: an error, not a silent success.
        assert!(confine_new(&udp_sockets().unwrap()).is_err());
    }
}
