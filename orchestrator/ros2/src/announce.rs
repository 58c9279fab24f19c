//! Repeats the bridge's participant announcements (SPDP) to this machine's LAN addresses.
//!
//! Why: rmw_cyclonedds in ROS 2 Jazzy's LOCALHOST discovery range (multicast off,
//! `localhost` as the static peer) selects the LAN interface, and Cyclone DDS drops, without
//! a log line, a discovery packet that comes in on an interface it did not select. Packets
//! to 127.0.0.1 come in on `lo`; packets to the machine's LAN address come in on that
//! interface. RustDDS 0.15 announces a participant to same-machine peers at 127.0.0.1 only
//! (its localhost peers: the well-known SPDP ports of participants 0..12), so such a node
//! hears the bridge only if the bridge answers the burst of announcements the node sends
//! when it starts, that is only if the bridge was up first.
//!
//! How: a socket bound to 127.0.0.1 at the SPDP port of participant 11, the last of
//! RustDDS's localhost peers, receives every announcement the participant sends there; each
//! one that carries the bridge's own GUID prefix is sent on, unchanged, to the SPDP ports of
//! participants 0..=32 (rmw_cyclonedds's MaxAutoParticipantIndex) at every IPv4 address of
//! the machine's up, non-loopback interfaces. Nothing leaves the machine: those addresses
//! are the machine's own. A twelfth participant on the machine finds that port taken and
//! moves to the next, as it does for any taken port.

use agrisim_error::{err, Result};
use std::net::{Ipv4Addr, SocketAddrV4, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

/// RustDDS's localhost SPDP peers are participants 0..12 (`SPDP_LOCALHOST_PEER_COUNT`).
const LAST_LOCALHOST_PEER: u16 = 11;
/// Participant indices tried by rmw_cyclonedds's LOCALHOST range (MaxAutoParticipantIndex).
const PEER_INDICES: u16 = 33;

/// The well-known unicast SPDP port of participant `pid` in domain `domain` (DDSI-RTPS 2.5,
/// 9.6.1.1: PB 7400 + DG 250 x domain + d1 10 + PG 2 x pid).
pub fn spdp_port(domain: u16, pid: u16) -> u16 {
    7400 + 250 * domain + 10 + 2 * pid
}

/// The running repeater; stops when dropped.
pub struct Announcer {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

/// The socket that will catch the announcements, bound before the participant exists so
/// that its very first announcement is caught. None when the port is taken (another
/// participant uses it): the bridge then works as before, without the repeat.
pub fn listen(domain: u16) -> Option<UdpSocket> {
    UdpSocket::bind(SocketAddrV4::new(Ipv4Addr::LOCALHOST, spdp_port(domain, LAST_LOCALHOST_PEER))).ok()
}

/// The IPv4 addresses of this machine's up, non-loopback interfaces.
pub fn lan_addresses() -> Vec<Ipv4Addr> {
    let mut out: Vec<Ipv4Addr> = netdev::get_interfaces()
        .iter()
        .filter(|i| i.is_up() && !i.is_loopback())
        .flat_map(|i| i.ipv4.iter().map(|n| n.addr()))
        .filter(|a| !a.is_loopback())
        .collect();
    out.sort();
    out.dedup();
    out
}

impl Announcer {
    /// Repeats, from `socket` (see [`listen`]), the announcements of the participant whose
    /// GUID prefix is `prefix` to `targets`' SPDP ports of `domain`.
    pub fn start(socket: UdpSocket, domain: u16, prefix: [u8; 12], targets: Vec<Ipv4Addr>) -> Result<Announcer> {
        socket
            .set_read_timeout(Some(Duration::from_millis(100)))
            .map_err(|e| err!("ROS 2 bridge: announcement repeater: {e}"))?;
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let thread = std::thread::Builder::new()
            .name("agrisim SPDP repeat".into())
            .spawn(move || repeat(&socket, domain, prefix, &targets, &flag))
            .map_err(|e| err!("ROS 2 bridge: announcement repeater: {e}"))?;
        Ok(Announcer { stop, thread: Some(thread) })
    }
}

impl Drop for Announcer {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The repeater's loop: until `stop`, each datagram that is an RTPS message from the
/// participant `prefix` goes to every target's SPDP ports.
fn repeat(socket: &UdpSocket, domain: u16, prefix: [u8; 12], targets: &[Ipv4Addr], stop: &AtomicBool) {
    let mut buf = vec![0u8; 65536];
    while !stop.load(Ordering::Relaxed) {
        let Ok(n) = socket.recv(&mut buf) else { continue };
        if !from_participant(&buf[..n], &prefix) {
            continue;
        }
        for &a in targets {
            for pid in 0..PEER_INDICES {
                // A port nobody listens on answers "unreachable", which an unconnected
                // socket does not report: nothing to handle.
                let _ = socket.send_to(&buf[..n], SocketAddrV4::new(a, spdp_port(domain, pid)));
            }
        }
    }
}

/// True if `msg` is an RTPS message (header: "RTPS", version, vendor, GUID prefix) sent by
/// the participant with GUID prefix `prefix`.
fn from_participant(msg: &[u8], prefix: &[u8; 12]) -> bool {
    msg.len() > 20 && &msg[..4] == b"RTPS" && &msg[8..20] == prefix
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ports_follow_the_rtps_mapping() {
        assert_eq!(spdp_port(0, 0), 7410);
        assert_eq!(spdp_port(0, 11), 7432);
        assert_eq!(spdp_port(1, 0), 7660);
    }

    #[test]
    fn only_the_bridges_own_messages_are_repeated() {
        let prefix = [7u8; 12];
        let mut msg = b"RTPS\x02\x04\x01\x12".to_vec();
        msg.extend_from_slice(&prefix);
        msg.extend_from_slice(&[0; 8]);
        assert!(from_participant(&msg, &prefix));
        assert!(!from_participant(&msg, &[8u8; 12]));
        assert!(!from_participant(&msg[..20], &prefix));
        msg[0] = b'X';
        assert!(!from_participant(&msg, &prefix));
    }

    #[test]
    fn repeats_to_each_target_port_and_stops_when_dropped() {
        // Listen where the repeat goes (127.0.0.2 stands for a LAN address), on a domain
        // whose ports nothing else here uses.
        let _serial = crate::SOCKET_TESTS.lock().unwrap_or_else(|e| e.into_inner());
        let domain = 77;
        let catch = listen(domain).expect("the SPDP port of participant 11 in domain 77 is free");
        let targets = vec![Ipv4Addr::new(127, 0, 0, 2)];
        let seen: Vec<UdpSocket> = (0..3)
            .filter_map(|pid| UdpSocket::bind((Ipv4Addr::new(127, 0, 0, 2), spdp_port(domain, pid))).ok())
            .collect();
        assert_eq!(seen.len(), 3);
        let prefix = [9u8; 12];
        let a = Announcer::start(catch, domain, prefix, targets).unwrap();
        let tx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let to = (Ipv4Addr::LOCALHOST, spdp_port(domain, LAST_LOCALHOST_PEER));
        tx.send_to(b"RTPS\x02\x04\x01\x12XXXXXXXXXXXX-other", to).unwrap();
        let mut mine = b"RTPS\x02\x04\x01\x12".to_vec();
        mine.extend_from_slice(&prefix);
        mine.extend_from_slice(b"-mine");
        tx.send_to(&mine, to).unwrap();
        let mut buf = [0u8; 64];
        for s in &seen {
            s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
            let n = s.recv(&mut buf).unwrap();
            assert_eq!(&buf[..n], &mine[..], "only the bridge's own message, unchanged");
        }
        drop(a);
        // Stopped: the port is free again.
        assert!(listen(domain).is_some());
    }
}
