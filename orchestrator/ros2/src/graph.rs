//! The bridge in the ROS 2 graph. The rmw layers (rmw_cyclonedds, rmw_fastrtps) say which ROS 2
//! nodes a DDS participant holds, and each node's readers and writers, on the
//! `ros_discovery_info` topic (type `rmw_dds_common/msg/ParticipantEntitiesInfo`, reliable,
//! transient local, keep last 1, no `rt/` prefix); `ros2 node list` and `ros2 topic info -v`
//! read it. The bridge announces itself as one node, `/agrisim`.
//!
//! The message's `Gid` differs by distro: `char[24]` up to Humble (the 16-byte GUID, then
//! zeros), `char[16]` from Iron on (Jazzy). A peer of the other distro misreads the sample (in
//! a test, a Jazzy-layout reader of the Humble layout saw the participant holding no node), so
//! the distro is chosen (`--ros2-distro`, Jazzy by default).

use agrisim_msgs::cdr::CdrWriter;

/// The DDS topic of the graph information.
pub const TOPIC: &str = "ros_discovery_info";
/// Its DDS type name.
pub const TYPE: &str = "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_";
/// The bridge's node: namespace and name.
pub const NODE: (&str, &str) = ("/", "agrisim");

/// The ROS 2 distro whose `Gid` layout the graph information follows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Distro {
    /// Humble and earlier: 24-byte Gid.
    Humble,
    /// Iron, Jazzy and later: 16-byte Gid.
    Jazzy,
}

impl Distro {
    /// A distro name: `humble`, `iron`, `jazzy`, `kilted` or `rolling`.
    pub fn parse(name: &str) -> Result<Distro, String> {
        match name {
            "humble" => Ok(Distro::Humble),
            "iron" | "jazzy" | "kilted" | "rolling" => Ok(Distro::Jazzy),
            other => Err(format!("unknown ROS 2 distro '{other}' (humble, iron, jazzy, kilted or rolling)")),
        }
    }

    fn gid_len(self) -> usize {
        match self {
            Distro::Humble => 24,
            Distro::Jazzy => 16,
        }
    }
}

/// The CDR of a ParticipantEntitiesInfo: participant `participant` (a 16-byte DDS GUID) holding
/// the one node [`NODE`] with these readers and writers.
pub fn participant_info(distro: Distro, participant: [u8; 16], readers: &[[u8; 16]], writers: &[[u8; 16]]) -> Vec<u8> {
    let mut w = CdrWriter::new();
    let gid = |w: &mut CdrWriter, g: &[u8; 16]| {
        for i in 0..distro.gid_len() {
            w.write_u8(g.get(i).copied().unwrap_or(0));
        }
    };
    gid(&mut w, &participant);
    w.write_sequence_len(1);
    w.write_string(NODE.0);
    w.write_string(NODE.1);
    for set in [readers, writers] {
        w.write_sequence_len(set.len());
        for g in set {
            gid(&mut w, g);
        }
    }
    w.into_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layouts() {
        let p = [1u8; 16];
        let (r, wr) = ([[2u8; 16]], [[3u8; 16], [4u8; 16]]);
        let j = participant_info(Distro::Jazzy, p, &r, &wr);
        let h = participant_info(Distro::Humble, p, &r, &wr);
        // Header, gid, node count, two strings ("/" and "agrisim" with their NULs, aligned),
        // then the two Gid sequences.
        assert_eq!(&j[..4], &[0, 1, 0, 0]);
        assert_eq!(&j[4..20], &[1u8; 16]);
        assert_eq!(&j[20..24], &1u32.to_le_bytes());
        assert_eq!(&h[4..28], &[[1u8; 16].as_slice(), &[0u8; 8]].concat()[..]);
        // Jazzy: strings at 24 ("/": 4 + 2, pad to 32), "agrisim" at 32 (4 + 8), readers at 44.
        assert_eq!(&j[24..30], &[2, 0, 0, 0, b'/', 0]);
        assert_eq!(&j[32..44], &[&8u32.to_le_bytes()[..], b"agrisim\0"].concat()[..]);
        assert_eq!(&j[44..48], &1u32.to_le_bytes());
        assert_eq!(&j[48..64], &[2u8; 16]);
        assert_eq!(&j[64..68], &2u32.to_le_bytes());
        assert_eq!(j.len(), 68 + 32);
        assert_eq!(h.len(), j.len() + 8 + 8 + 16);
        assert_eq!(Distro::parse("jazzy"), Ok(Distro::Jazzy));
        assert!(Distro::parse("foxy").is_err());
    }
}
