//! The sidecar end to end in one process: taps, a late publisher, malformed samples, the proxy filter, replay.

mod live_common;

use std::time::Duration;

use iceoryx2::prelude::*;
use live_common::*;

#[test]
fn late_battery_makes_the_recurrence_fail_and_replay_agrees() {
    let svc = unique("battery");
    let verdict_svc = unique("verdicts");
    let config = format!(
        "[verdicts]\nservice = \"{verdict_svc}\"\n{}",
        battery_topic(&svc)
    );
    let run = Running::start(&config, "late");
    let node = node();
    let verdicts = node
        .service_builder(&ServiceName::new(&verdict_svc).unwrap())
        .publish_subscribe::<[u8]>()
        .open()
        .unwrap()
        .subscriber_builder()
        .create()
        .unwrap();
    let p = publisher(&node, &svc);
    // On time: every 20 ms against a bound of 300 ms.
    for i in 0..10u64 {
        send(&p, &battery(80, i));
        std::thread::sleep(Duration::from_millis(20));
    }
    run.wait_judged(10);
    // Late: 700 ms between samples; heartbeat points see the window expire.
    for i in 10..12u64 {
        std::thread::sleep(Duration::from_millis(700));
        send(&p, &battery(80, i));
    }
    run.wait_judged(12);
    // The verdict lines also go out on the iceoryx2 verdict service.
    let mut published = Vec::new();
    let t = std::time::Instant::now();
    while !published
        .iter()
        .any(|l: &String| l.contains("\"verdict\":\"false\""))
    {
        while let Some(s) = verdicts.receive().unwrap() {
            published.push(String::from_utf8(s.payload().to_vec()).unwrap());
        }
        assert!(t.elapsed() < Duration::from_secs(20), "{published:?}");
        std::thread::sleep(Duration::from_millis(2));
    }
    let done = run.finish();
    assert!(
        done.lines.ends_with(&published[published.len() - 1..]),
        "{published:?}"
    );
    let rec = done.verdicts_of("battery_recurrence");
    assert_eq!(
        rec.first().map(String::as_str),
        Some("currently_true"),
        "{:?}",
        done.lines
    );
    // H(...) once false stays false: the final verdict is `false`.
    assert_eq!(
        rec.last().map(String::as_str),
        Some("false"),
        "{:?}",
        done.lines
    );
    assert!(
        !rec.iter().any(|v| v == "unknown"),
        "nothing was lost: {rec:?}"
    );
    assert_eq!(done.verdicts_of("absence"), ["currently_true"]);
    let s = &done.report.sources[0];
    assert_eq!((s.samples, s.lost, s.malformed, s.restarts), (12, 0, 0, 0));
    done.assert_replay_matches();
}

#[test]
fn malformed_and_lost_samples_are_counted_and_make_readers_unknown() {
    let svc = unique("battery");
    let run = Running::start(&battery_topic(&svc), "malformed");
    let node = node();
    let p = publisher(&node, &svc);
    send(&p, &battery(80, 0));
    run.wait_judged(1);
    send(&p, &[1, 2, 3]); // wrong size
    send(&p, &battery(80, 1));
    send(&p, &battery(80, 5)); // 2, 3 and 4 never came: lost
    run.wait_judged(4);
    // Keep publishing on time past the 300 ms horizon: the properties judge again.
    for i in 6..30u64 {
        send(&p, &battery(80, i));
        std::thread::sleep(Duration::from_millis(20));
    }
    run.wait_judged(29);
    let done = run.finish();
    let s = &done.report.sources[0];
    assert_eq!((s.samples, s.malformed, s.lost), (27, 1, 3), "{}", done.log);
    assert!(
        done.log
            .contains("malformed sample: payload of 3 bytes, the layout has 16"),
        "{}",
        done.log
    );
    assert!(
        done.log.contains("3 samples lost (sequence 2 to 5)"),
        "{}",
        done.log
    );
    for prop in ["absence", "battery_recurrence"] {
        let v = done.verdicts_of(prop);
        assert_eq!(
            v[..2],
            ["currently_true", "unknown"],
            "{prop}: {:?}",
            done.lines
        );
        assert_eq!(
            v.last().map(String::as_str),
            Some("currently_true"),
            "{prop}: {:?}",
            done.lines
        );
        assert!(
            v.iter().all(|x| x == "currently_true" || x == "unknown"),
            "{prop}: {v:?}"
        );
    }
    // The request property reads battery_level too, so it is affected the same way.
    assert_eq!(done.verdicts_of("poi_needs_battery")[1], "unknown");
    done.assert_replay_matches();
}

fn real_server(
    node: &Node<ipc::Service>,
    svc: &str,
) -> iceoryx2::port::server::Server<ipc::Service, [u8], (), [u8], ()> {
    node.service_builder(&ServiceName::new(svc).unwrap())
        .request_response::<[u8], [u8]>()
        .open_or_create()
        .unwrap()
        .server_builder()
        .initial_max_slice_len(16)
        .create()
        .unwrap()
}

/// Sends `req` through the monitor and returns the reply, answering as the real server meanwhile.
fn call(
    client: &iceoryx2::port::client::Client<ipc::Service, [u8], (), [u8], ()>,
    server: &iceoryx2::port::server::Server<ipc::Service, [u8], (), [u8], ()>,
    req: &[u8],
) -> Vec<u8> {
    let pending = client
        .loan_slice_uninit(req.len())
        .unwrap()
        .write_from_slice(req)
        .send()
        .unwrap();
    let t = std::time::Instant::now();
    loop {
        if let Some(r) = server.receive().unwrap() {
            // The real server answers [1, request byte].
            let answer = [1u8, r.payload()[0]];
            r.loan_slice_uninit(2)
                .unwrap()
                .write_from_slice(&answer)
                .send()
                .unwrap();
        }
        if let Some(resp) = pending.receive().unwrap() {
            return resp.payload().to_vec();
        }
        assert!(t.elapsed() < Duration::from_secs(20), "no reply");
        std::thread::sleep(Duration::from_millis(1));
    }
}

#[test]
fn proxy_filter_blocks_a_request_that_would_falsify_and_forwards_the_rest() {
    let topic = unique("battery");
    let svc = unique("poi");
    let config = format!(
        "{}[[service]]\nservice = \"{svc}\"\naction = \"filter\"\nsize = 1\nevent = \"poi_request\"\n\
         properties = [\"poi_needs_battery\"]\nerror = [238]\n\
         [[service.field]]\nvar = \"poi\"\noffset = 0\ntype = \"u8\"\n",
        battery_topic(&topic)
    );
    let run = Running::start(&config, "filter");
    let node = node();
    let server = real_server(&node, &format!("{svc}.real"));
    let client = node
        .service_builder(&ServiceName::new(&svc).unwrap())
        .request_response::<[u8], [u8]>()
        .open_or_create()
        .unwrap()
        .client_builder()
        .initial_max_slice_len(16)
        .create()
        .unwrap();
    let p = publisher(&node, &topic);
    send(&p, &battery(80, 0));
    // Judged after the sample (the monitor drains taps before each request): allowed.
    assert_eq!(call(&client, &server, &[7]), [1, 7]);
    send(&p, &battery(10, 1));
    // Battery low: the request would make poi_needs_battery false: blocked with the error reply.
    assert_eq!(call(&client, &server, &[8]), [238]);
    send(&p, &battery(90, 2));
    assert_eq!(call(&client, &server, &[9]), [1, 9]);
    run.wait_judged(6);
    let done = run.finish();
    let s = &done.report.sources[1];
    assert_eq!(
        (s.samples, s.forwarded, s.blocked),
        (3, 2, 1),
        "{}",
        done.log
    );
    // The refused request left no trace: the property never turned false.
    assert_eq!(
        done.verdicts_of("poi_needs_battery"),
        ["currently_true"],
        "{:?}",
        done.lines
    );
    done.assert_replay_matches();
}

#[test]
fn proxy_log_forwards_and_judges_every_request() {
    let svc = unique("poi");
    let config = format!(
        "[[service]]\nservice = \"{svc}\"\naction = \"log\"\nsize = 1\nevent = \"poi_request\"\n\
         [[service.field]]\nvar = \"poi\"\noffset = 0\ntype = \"u8\"\n"
    );
    let run = Running::start(&config, "log");
    let node = node();
    let server = real_server(&node, &format!("{svc}.real"));
    let client = node
        .service_builder(&ServiceName::new(&svc).unwrap())
        .request_response::<[u8], [u8]>()
        .open_or_create()
        .unwrap()
        .client_builder()
        .initial_max_slice_len(16)
        .create()
        .unwrap();
    assert_eq!(call(&client, &server, &[3]), [1, 3]);
    // A malformed request is forwarded by `log` (it only watches) but counted.
    let pending = client
        .loan_slice_uninit(2)
        .unwrap()
        .write_from_slice(&[4, 4])
        .send()
        .unwrap();
    let t = std::time::Instant::now();
    let reply = loop {
        if let Some(r) = server.receive().unwrap() {
            r.loan_slice_uninit(1)
                .unwrap()
                .write_from_slice(&[5])
                .send()
                .unwrap();
        }
        if let Some(resp) = pending.receive().unwrap() {
            break resp.payload().to_vec();
        }
        assert!(t.elapsed() < Duration::from_secs(20), "no reply");
        std::thread::sleep(Duration::from_millis(1));
    };
    assert_eq!(reply, [5]);
    run.wait_judged(2);
    let done = run.finish();
    let s = &done.report.sources[0];
    assert_eq!(
        (s.samples, s.malformed, s.forwarded, s.blocked),
        (1, 1, 2, 0),
        "{}",
        done.log
    );
    done.assert_replay_matches();
}

#[test]
fn a_topic_without_safe_overflow_is_refused_because_a_tap_could_block_its_publisher() {
    let svc = unique("strict");
    let node = node();
    let _service = node
        .service_builder(&ServiceName::new(&svc).unwrap())
        .publish_subscribe::<[u8]>()
        .enable_safe_overflow(false)
        .create()
        .unwrap();
    let spec = codegen::compile_spec(SPEC, "test.hspec").unwrap();
    let config =
        hindsight::live::config::Config::parse(&battery_topic(&svc), "t.toml", &spec).unwrap();
    match hindsight::live::Sidecar::new(&config, &spec, false) {
        Ok(_) => panic!("tapped a service without safe overflow"),
        Err(e) => assert!(e.to_string().contains("no safe overflow"), "{e}"),
    }
}
