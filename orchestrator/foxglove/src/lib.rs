//! agrisim-foxglove: the bus served live to Foxglove (`--foxglove [ADDR]`). Every topic becomes
//! a channel with its `ros2msg` schema (the same text the MCAP carries) and `cdr` encoding,
//! its messages go out as the raw CDR on the bus, stamped with simulated time, and the
//! server's clock follows simulated time, so Foxglove's panels show the run as it happens.
//! Bound to 127.0.0.1 unless the user gives another address.

use agrisim_bus::{Bus, Node, Tap};
use agrisim_error::{err, Result};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::rosgraph_msgs::Clock;
use agrisim_msgs::Message;
use foxglove::websocket::Capability;
use foxglove::{ChannelBuilder, Context, PartialMetadata, RawChannel, Schema, WebSocketServer, WebSocketServerHandle};
use std::collections::BTreeMap;
use std::net::SocketAddr;
use std::sync::Arc;

/// The default address: loopback only, Foxglove's default port.
pub const DEFAULT_ADDR: &str = "127.0.0.1:8765";

pub struct FoxgloveView {
    context: Arc<Context>,
    server: Option<WebSocketServerHandle>,
    channels: BTreeMap<String, Arc<RawChannel>>,
    tap: Tap,
}

impl FoxgloveView {
    /// Starts the server on `addr` (port 0: any free port); returns it and the bound port.
    pub fn start(addr: SocketAddr) -> Result<(FoxgloveView, u16)> {
        let context = Context::new();
        let server = WebSocketServer::new()
            .name("agrisim")
            // The clock Foxglove shows is simulated time.
            .capabilities([Capability::Time])
            .bind(addr.ip().to_string(), addr.port())
            .context(&context)
            .start_blocking()
            .map_err(|e| err!("Foxglove server on {addr}: {e}"))?;
        let port = server.port();
        Ok((FoxgloveView { context, server: Some(server), channels: BTreeMap::new(), tap: Tap::default() }, port))
    }

    fn log(&mut self, topic: &str, ros_type: &str, t_ns: i64, cdr: &[u8]) -> Result<()> {
        if !self.channels.contains_key(topic) {
            let text = agrisim_msgs::ros2msg_schema(ros_type)
                .ok_or_else(|| err!("Foxglove view: topic {topic}: no .msg definition for {ros_type}"))?;
            let channel = ChannelBuilder::new(topic)
                .message_encoding("cdr")
                .schema(Schema::new(ros_type, "ros2msg", text.into_bytes()))
                .context(&self.context)
                .build_raw()
                .map_err(|e| err!("Foxglove view: channel {topic}: {e}"))?;
            self.channels.insert(topic.to_string(), channel);
        }
        self.channels[topic].log_with_meta(cdr, PartialMetadata { log_time: Some(t_ns.max(0) as u64) });
        Ok(())
    }
}

impl Node for FoxgloveView {
    fn name(&self) -> &str {
        "foxglove"
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        for (topic, ty, s) in self.tap.take(bus, |_| true) {
            self.log(&topic, &ty, s.time_ns, &s.cdr)?;
        }
        self.log("/clock", Clock::TYPE_NAME, t_ns, &Clock { clock: Time::from_nanos(t_ns) }.to_cdr())?;
        if let Some(s) = &self.server {
            s.broadcast_time(t_ns.max(0) as u64);
        }
        Ok(())
    }
}

impl Drop for FoxgloveView {
    /// Stops the server (its port is free for the next run).
    fn drop(&mut self) {
        if let Some(s) = self.server.take() {
            s.stop().wait_blocking();
        }
    }
}
