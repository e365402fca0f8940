//! `hindsight run --ros2 --external NODE`: the services node NODE called, served by the run
//! to ROS 2 clients over DDS, as ROS 2's Cyclone DDS middleware serves them.
//!
//! # The rule (rmw_cyclonedds_cpp, `src/rmw_node.cpp` and `src/serdata.hpp`)
//!
//! - A service `/s` of type `pkg/srv/Name` is two DDS topics: requests on `rq/sRequest`
//!   typed `pkg::srv::dds_::Name_Request_`, replies on `rr/sReply` typed
//!   `pkg::srv::dds_::Name_Response_` (`rmw_init_cs`; [`ros2::dds::service_topics`]).
//! - Every request and every reply starts with a header of two CDR fields before the
//!   message's own (`cdds_request_header_t`, written by the service type's serdata):
//!   `guid`, a `uint64` naming the client (its request writer's instance handle,
//!   `rmw_send_request`), and `seq`, an `int64` that numbers the client's requests.
//! - A server answers a request with its header unchanged (`rmw_send_response` copies
//!   `guid` and `seq`); a client takes the replies whose `guid` is its own
//!   (`rmw_take_response` filters on it), and matches `seq` to its call.
//! - Both use ROS 2's service QoS (`rmw_qos_profile_services_default`: reliable,
//!   volatile, keep last 10).
//!
//! The 16-byte header keeps the body's 8-byte alignment, so a request's fields are read
//! by the recordings' CDR reader once the header is taken out, and a reply is our CDR
//! writer's message with the header put in after the encapsulation. Clients of ROS 2's
//! Fast DDS middleware carry the request id in the RTPS related-sample identity instead
//! of a header: they are not served.
//!
//! A request becomes the NODE's request event in the model (`srv_<s>_req_client_<NODE>`,
//! its `ros_fields__*` parameters from the request's fields); the model's answer to NODE
//! (`srv_<s>_response_client_<NODE>`) goes back, in order, to the oldest request waiting.

use std::collections::VecDeque;

use monitor_core::Value as MValue;
use ros2::cdr::Decoder;
use ros2::cdr_write::{encode, Val};
use ros2::dds::{service_topics, type_name, Participant, Qos, Reader, Received, Writer};
use ros2::schema::{Definitions, Schema};

use crate::expr::Ty;
use crate::publish_dds::{field_path, message_val};
use crate::sim::{CompiledModel, EventId, Inbox, Scalar, SentMessage};
use crate::LiveError;

/// The request id header's length: `uint64 guid`, `int64 seq`.
const HEADER: usize = 16;

/// One service the run serves to ROS 2 clients.
pub struct ServiceRoute {
    /// The ROS service (`/adder/add`).
    pub service: String,
    /// Its type as declared (`example_interfaces/AddTwoInts`).
    pub type_name: String,
    /// The external node's request event (what the model's server receives).
    pub request: EventId,
    /// The model's answer to the external node.
    pub response: EventId,
}

/// What one served service did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ServedStats {
    /// The ROS service.
    pub service: String,
    /// Requests taken from ROS 2 clients and posted into the model.
    pub requests: u64,
    /// Answers sent back.
    pub answered: u64,
    /// Requests that do not decode (no answer).
    pub malformed: u64,
    /// The last reason a request did not decode, or an answer could not be sent.
    pub last_error: Option<String>,
}

struct Served {
    route: ServiceRoute,
    /// `(model parameter, decoder slot, its type)` of every request field carried.
    params: Vec<(usize, usize, Ty)>,
    decoder: Decoder,
    reply_schema: Schema,
    /// `(model parameter of the answer, field path)`.
    reply_fields: Vec<(usize, String)>,
    reader: Reader,
    writer: Writer,
    /// The headers of the requests posted into the model and not answered yet.
    waiting: VecDeque<[u8; HEADER]>,
    stats: ServedStats,
}

/// Serves the routes' services on DDS: requests into the model, its answers back.
pub struct DdsServices {
    _participant: Participant,
    served: Vec<Served>,
    buf: Vec<Received>,
}

fn scalar_ty(ty: &Ty) -> Option<monitor_core::Ty> {
    match ty {
        Ty::Bool => Some(monitor_core::Ty::Bool),
        Ty::Int => Some(monitor_core::Ty::Int),
        Ty::Float => Some(monitor_core::Ty::Float),
        _ => None,
    }
}

/// The `pkg/srv/Name_<part>` of a declared service type `pkg/Name` or `pkg/srv/Name`.
fn part_type(declared: &str, part: &str) -> Result<String, ros2::schema::SchemaError> {
    let (pkg, name) = ros2::schema::split_type_name(declared)?;
    Ok(format!("{pkg}/srv/{name}_{part}"))
}

impl DdsServices {
    /// Joins `domain` with one reader of requests and one writer of replies per route;
    /// a warning for every field that is not carried (strings, arrays, structs).
    pub fn new(
        domain: u16,
        model: &CompiledModel,
        routes: Vec<ServiceRoute>,
        defs: &dyn Definitions,
        warnings: &mut Vec<String>,
    ) -> Result<DdsServices, LiveError> {
        let participant = Participant::new(domain).map_err(LiveError::Dds)?;
        let mut served = Vec::new();
        for route in routes {
            let s = &route.service;
            let schema = |error| LiveError::Service {
                service: s.clone(),
                error,
            };
            let req_type = part_type(&route.type_name, "Request").map_err(schema)?;
            let resp_type = part_type(&route.type_name, "Response").map_err(schema)?;
            let req_schema = Schema::resolve(&req_type, defs).map_err(schema)?;
            let reply_schema = Schema::resolve(&resp_type, defs).map_err(schema)?;
            let mut decoder = Decoder::new(req_schema, &[]);
            let mut params = Vec::new();
            for (i, (pname, ty)) in model.event_params(route.request).iter().enumerate() {
                let Some(path) = field_path(pname) else {
                    continue;
                };
                let Some(mty) = scalar_ty(ty) else {
                    warnings.push(format!(
                        "service {s}: request field `{path}` ({ty:?}) is not carried from DDS \
                         (only booleans and numbers); the model sees its default"
                    ));
                    continue;
                };
                match decoder.add(&path, mty) {
                    Ok(slot) => params.push((i, slot, ty.clone())),
                    Err(m) => warnings.push(format!("service {s}: {m}")),
                }
            }
            let mut reply_fields = Vec::new();
            let zero = Val::zero(&reply_schema, 0);
            for (i, (pname, ty)) in model.event_params(route.response).iter().enumerate() {
                let Some(path) = field_path(pname) else {
                    continue;
                };
                if scalar_ty(ty).is_none() && *ty != Ty::Str {
                    warnings.push(format!(
                        "service {s}: reply field `{path}` ({ty:?}) is sent as zeros on DDS"
                    ));
                    continue;
                }
                let mut probe = zero.clone();
                match probe.set(&reply_schema, &path, Val::Int(0)) {
                    Ok(()) => reply_fields.push((i, path)),
                    Err(m) => warnings.push(format!("service {s}: {m}")),
                }
            }
            let (rq, rr) = service_topics(s);
            let dds = LiveError::Dds;
            let reader = participant
                .dds_reader(&rq, type_name(&req_type).map_err(dds)?, Qos::ros_default())
                .map_err(dds)?;
            let writer = participant
                .dds_writer(&rr, type_name(&resp_type).map_err(dds)?, Qos::ros_default())
                .map_err(dds)?;
            served.push(Served {
                stats: ServedStats {
                    service: s.clone(),
                    ..ServedStats::default()
                },
                route,
                params,
                decoder,
                reply_schema,
                reply_fields,
                reader,
                writer,
                waiting: VecDeque::new(),
            });
        }
        Ok(DdsServices {
            _participant: participant,
            served,
            buf: Vec::new(),
        })
    }

    /// Takes every request that arrived and queues it in `inbox` as the external node's
    /// request. A request that does not decode is counted and gets no answer.
    pub fn poll(&mut self, inbox: &mut Inbox) {
        for s in &mut self.served {
            self.buf.clear();
            if let Err(e) = s.reader.take(&mut self.buf) {
                s.stats.last_error = Some(e.to_string());
                continue;
            }
            for r in &self.buf {
                match decode_request(s, &r.data) {
                    Ok((header, params)) => {
                        s.stats.requests += 1;
                        inbox.push(s.route.request, params);
                        s.waiting.push_back(header);
                    }
                    Err(e) => {
                        s.stats.malformed += 1;
                        s.stats.last_error = Some(e.to_string());
                    }
                }
            }
        }
    }

    /// Sends `msg` back to the oldest waiting client if it is the model's answer to the
    /// external node.
    pub fn answer(&mut self, model: &CompiledModel, msg: &SentMessage<'_>) {
        let Some(s) = self
            .served
            .iter_mut()
            .find(|s| s.route.response == msg.event())
        else {
            return;
        };
        let Some(header) = s.waiting.pop_front() else {
            return;
        };
        let (v, result) = message_val(model, msg, &s.reply_schema, &s.reply_fields);
        let sent = result
            .and_then(|()| encode(&s.reply_schema, &v))
            .map_err(|e| e.to_string())
            .and_then(|cdr| {
                s.writer
                    .write(&with_header(&cdr, &header))
                    .map_err(|e| e.to_string())
            });
        match sent {
            Ok(()) => s.stats.answered += 1,
            Err(e) => s.stats.last_error = Some(e),
        }
    }

    /// What each served service did so far.
    pub fn stats(&self) -> impl Iterator<Item = &ServedStats> {
        self.served.iter().map(|s| &s.stats)
    }

    /// Waits (up to `max_wait` per service) until the clients acknowledged every reply.
    pub fn flush(&self, max_wait: std::time::Duration) {
        for s in &self.served {
            if s.writer.matched() > 0 {
                s.writer.wait_acked(max_wait);
            }
        }
    }
}

/// A request: its id header and its fields as the model's parameters.
type Request = ([u8; HEADER], Vec<(usize, Scalar)>);

/// Why a request sample was not posted into the model.
#[derive(Debug)]
enum RequestError {
    /// Shorter than the encapsulation and the request id: its length.
    Short(usize),
    /// The fields do not decode as the service's request.
    Cdr {
        service: String,
        error: ros2::cdr::CdrError,
    },
}

impl std::fmt::Display for RequestError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RequestError::Short(n) => write!(
                f,
                "a request of {n} byte(s) is shorter than the encapsulation and the 16-byte \
                 request id"
            ),
            RequestError::Cdr { service, error } => write!(f, "{service}: {error}"),
        }
    }
}

/// A request's header and its fields as the model's parameters.
fn decode_request(s: &Served, data: &[u8]) -> Result<Request, RequestError> {
    let (header, body) = split_header(data).ok_or(RequestError::Short(data.len()))?;
    let mut out = vec![MValue::Bool(false); s.decoder.slots()];
    let mut present = vec![false; s.decoder.slots()];
    s.decoder
        .decode(&body, &mut out, &mut present)
        .map_err(|error| RequestError::Cdr {
            service: s.route.service.clone(),
            error,
        })?;
    let params = s
        .params
        .iter()
        .filter(|(_, slot, _)| present[*slot])
        .filter_map(|(param, slot, _)| {
            Some((
                *param,
                match &out[*slot] {
                    MValue::Bool(b) => Scalar::Bool(*b),
                    MValue::Int(i) => Scalar::Int(*i),
                    MValue::Float(x) => Scalar::Float(*x),
                    MValue::Str(_) => return None,
                },
            ))
        })
        .collect();
    Ok((header, params))
}

/// `(request id header, the message without it)` of a request sample (encapsulation
/// header, `guid`, `seq`, fields); `None` when it is too short to have them.
fn split_header(data: &[u8]) -> Option<([u8; HEADER], Vec<u8>)> {
    let header: [u8; HEADER] = data.get(4..4 + HEADER)?.try_into().ok()?;
    let mut body = Vec::with_capacity(data.len() - HEADER);
    body.extend_from_slice(&data[..4]);
    body.extend_from_slice(&data[4 + HEADER..]);
    Some((header, body))
}

/// A reply: the encapsulation header of `cdr`, the request's header as it came (same
/// byte order: the client wrote both), then the message.
fn with_header(cdr: &[u8], header: &[u8; HEADER]) -> Vec<u8> {
    let mut out = Vec::with_capacity(cdr.len() + HEADER);
    out.extend_from_slice(&cdr[..4.min(cdr.len())]);
    out.extend_from_slice(header);
    out.extend_from_slice(cdr.get(4..).unwrap_or_default());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_request_id_is_taken_out_and_put_back() {
        // Little-endian CDR: encapsulation, guid 0x0102..08, seq 5, then an int64 42.
        let mut data = vec![0, 1, 0, 0];
        data.extend_from_slice(&0x0807_0605_0403_0201u64.to_le_bytes());
        data.extend_from_slice(&5i64.to_le_bytes());
        data.extend_from_slice(&42i64.to_le_bytes());
        let (header, body) = split_header(&data).unwrap();
        assert_eq!(header[..8], [1, 2, 3, 4, 5, 6, 7, 8]);
        assert_eq!(body, [0, 1, 0, 0, 42, 0, 0, 0, 0, 0, 0, 0]);
        assert_eq!(with_header(&body, &header), data);
        assert!(split_header(&data[..19]).is_none());
    }
}
