//! agrisim-foxglove: the bus served live to Foxglove (`--foxglove [ADDR]`). Every topic becomes
//! a channel with its `ros2msg` schema (the same text the MCAP carries) and `cdr` encoding,
//! its messages go out as the raw CDR on the bus, stamped with simulated time, and the
//! server's clock follows simulated time, so Foxglove's panels show the run as it happens.
//! Bound to 127.0.0.1 unless the user gives another address.
//!
//! Latched topics (`agrisim_bus::LATCHED_TOPICS`: /robot_description, the greenhouse
//! markers, /tf_static, /map) are published once, usually before a viewer connects. As ROS 2's
//! transient local durability does, a client that subscribes to one later gets its last
//! message, and only that client: a [`ServerListener`] sends it on the subscription. The
//! server registers the subscription with its channel before it calls the listener, and the
//! step thread stores a latched message and broadcasts it under one lock, so a subscriber
//! gets the message either from the broadcast or from the listener (at worst both), never
//! neither. /tf_static has many publishers (robot_state_publisher, the map -> odom of a run
//! without localization): as tf2's static buffer does, its transforms are merged by child
//! frame, and what goes out is the whole set.
//!
//! The foxglove crate (0.30.3) queues a channel's advertisement to a connected client before
//! it records the channel as advertised to that client, so a client that answers at once
//! (and a loaded machine delays the server) gets "Unknown channel ID" for its subscription,
//! and never the messages: a channel created while a client is connected can be lost to it.
//! Channels that exist when a client connects are advertised before the server reads the
//! client's first message, without that race. So [`FoxgloveView::start_with`] creates the
//! channels of the topics known before the run (the system's, the viewer topics) before the
//! server starts; only topics that first appear later are advertised live.

use agrisim_bus::{Bus, Node, Tap};
use agrisim_error::{err, Result};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::TransformStamped;
use agrisim_msgs::rosgraph_msgs::Clock;
use agrisim_msgs::tf2_msgs::TFMessage;
use agrisim_msgs::Message;
use foxglove::websocket::{Capability, ChannelView, Client, ServerListener};
use foxglove::{ChannelBuilder, Context, PartialMetadata, RawChannel, Schema, WebSocketServer, WebSocketServerHandle};
use std::collections::BTreeMap;
use std::net::SocketAddr;
use std::sync::{Arc, Mutex, PoisonError};

/// Static transforms (tf2_msgs/TFMessage, latched, merged by child frame).
const TF_STATIC: &str = "/tf_static";

/// The default address: loopback only, Foxglove's default port.
pub const DEFAULT_ADDR: &str = "127.0.0.1:8765";

pub struct FoxgloveView {
    context: Arc<Context>,
    server: Option<WebSocketServerHandle>,
    channels: BTreeMap<String, Arc<RawChannel>>,
    tap: Tap,
    /// The last message of each latched topic's channel, shared with the listener.
    latched: Arc<Latched>,
    /// /tf_static's transforms by child frame.
    static_tf: BTreeMap<String, TransformStamped>,
}

/// The last message of each latched channel (channel, CDR) and the simulated time \[ns\] of
/// the last step: a late subscriber gets the message logged at that time, when it receives
/// it (as a ROS 2 subscriber of a transient local topic does), not before it connected.
#[derive(Default)]
struct Latched(Mutex<(LastMessages, u64)>);

/// Channel id -> (channel, CDR of its last message).
type LastMessages = BTreeMap<u64, (Arc<RawChannel>, Vec<u8>)>;

impl ServerListener for Latched {
    /// A new subscriber of a latched channel gets its last message.
    fn on_subscribe(&self, client: Client, channel: ChannelView) {
        let last = self.0.lock().unwrap_or_else(PoisonError::into_inner);
        if let Some((ch, cdr)) = last.0.get(&u64::from(channel.id())) {
            ch.log_with_meta_to_sink(cdr, PartialMetadata { log_time: Some(last.1) }, client.sink_id());
        }
    }
}

impl FoxgloveView {
    /// Starts the server on `addr` (port 0: any free port); returns it and the bound port.
    pub fn start(addr: SocketAddr) -> Result<(FoxgloveView, u16)> {
        FoxgloveView::start_with(addr, &[])
    }

    /// [`FoxgloveView::start`], with the channels of `known` (topic, ROS 2 type) created
    /// before the server starts (see the crate's documentation).
    pub fn start_with(addr: SocketAddr, known: &[(String, String)]) -> Result<(FoxgloveView, u16)> {
        let context = Context::new();
        let mut channels = BTreeMap::new();
        for (topic, ty) in known {
            if !channels.contains_key(topic) {
                channels.insert(topic.clone(), new_channel(&context, topic, ty)?);
            }
        }
        let latched = Arc::new(Latched::default());
        let server = WebSocketServer::new()
            .name("agrisim")
            // The clock Foxglove shows is simulated time.
            .capabilities([Capability::Time])
            .listener(latched.clone())
            .bind(addr.ip().to_string(), addr.port())
            .context(&context)
            .start_blocking()
            .map_err(|e| err!("Foxglove server on {addr}: {e}"))?;
        let port = server.port();
        let view = FoxgloveView {
            context,
            server: Some(server),
            channels,
            tap: Tap::default(),
            latched,
            static_tf: BTreeMap::new(),
        };
        Ok((view, port))
    }

    fn channel(&mut self, topic: &str, ros_type: &str) -> Result<Arc<RawChannel>> {
        if !self.channels.contains_key(topic) {
            let channel = new_channel(&self.context, topic, ros_type)?;
            self.channels.insert(topic.to_string(), channel);
        }
        let channel = &self.channels[topic];
        if channel.schema().is_some_and(|s| s.name != ros_type) {
            return Err(err!(
                "Foxglove view: topic {topic}: a {ros_type} message on a channel of {}",
                channel.schema().map_or("", |s| s.name.as_str())
            ));
        }
        Ok(channel.clone())
    }

    fn log(&mut self, topic: &str, ros_type: &str, t_ns: i64, cdr: &[u8]) -> Result<()> {
        let channel = self.channel(topic, ros_type)?;
        let meta = PartialMetadata { log_time: Some(t_ns.max(0) as u64) };
        if !agrisim_bus::is_latched(topic) {
            channel.log_with_meta(cdr, meta);
            return Ok(());
        }
        let cdr = if topic == TF_STATIC { self.merge_static_tf(cdr)? } else { cdr.to_vec() };
        // Stored and broadcast under the lock (see the crate's documentation).
        let mut last = self.latched.0.lock().unwrap_or_else(PoisonError::into_inner);
        channel.log_with_meta(&cdr, meta);
        last.0.insert(u64::from(channel.id()), (channel.clone(), cdr));
        Ok(())
    }

    /// /tf_static's transforms so far with those of `cdr` (a TFMessage), by child frame.
    fn merge_static_tf(&mut self, cdr: &[u8]) -> Result<Vec<u8>> {
        let msg = TFMessage::from_cdr(cdr).map_err(|e| err!("Foxglove view: /tf_static: {e}"))?;
        for t in msg.transforms {
            self.static_tf.insert(t.child_frame_id.clone(), t);
        }
        Ok(TFMessage { transforms: self.static_tf.values().cloned().collect() }.to_cdr())
    }
}

/// A channel of `topic` with its `ros2msg` schema and `cdr` encoding.
fn new_channel(context: &Arc<Context>, topic: &str, ros_type: &str) -> Result<Arc<RawChannel>> {
    let text = agrisim_msgs::ros2msg_schema(ros_type)
        .ok_or_else(|| err!("Foxglove view: topic {topic}: no .msg definition for {ros_type}"))?;
    ChannelBuilder::new(topic)
        .message_encoding("cdr")
        .schema(Schema::new(ros_type, "ros2msg", text.into_bytes()))
        .context(context)
        .build_raw()
        .map_err(|e| err!("Foxglove view: channel {topic}: {e}"))
}

impl Node for FoxgloveView {
    fn name(&self) -> &str {
        "foxglove"
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        for (topic, ty, s) in self.tap.take(bus, |_| true) {
            self.log(&topic, &ty, s.time_ns, &s.cdr)?;
        }
        self.latched.0.lock().unwrap_or_else(PoisonError::into_inner).1 = t_ns.max(0) as u64;
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
