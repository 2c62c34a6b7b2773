//! Just enough of the ROS 1 bag format 2.0 to build hostile bags by hand: records
//! (`header_len`, `name=value` fields, `data_len`, data), connections, messages and
//! chunks, and the bodies of LaserScan and JointState messages.

/// One `name=value` header field.
fn field(out: &mut Vec<u8>, name: &str, value: &[u8]) {
    out.extend(((name.len() + 1 + value.len()) as u32).to_le_bytes());
    out.extend(name.as_bytes());
    out.push(b'=');
    out.extend(value);
}

/// A record of header `fields` and `data`.
pub fn record(fields: &[(&str, &[u8])], data: &[u8]) -> Vec<u8> {
    let mut h = Vec::new();
    for (n, v) in fields {
        field(&mut h, n, v);
    }
    let mut out = Vec::new();
    out.extend((h.len() as u32).to_le_bytes());
    out.extend(h);
    out.extend((data.len() as u32).to_le_bytes());
    out.extend(data);
    out
}

/// The start of a bag: magic and a bag header record without index.
pub fn bag_start() -> Vec<u8> {
    let mut out = b"#ROSBAG V2.0\n".to_vec();
    out.extend(record(
        &[
            ("op", &[0x03]),
            ("index_pos", &0u64.to_le_bytes()),
            ("conn_count", &0u32.to_le_bytes()),
            ("chunk_count", &0u32.to_le_bytes()),
        ],
        &[],
    ));
    out
}

/// A connection record: `conn` is `topic` of ROS 1 type `type_name`.
pub fn connection(conn: u32, topic: &str, type_name: &str) -> Vec<u8> {
    let mut data = Vec::new();
    field(&mut data, "topic", topic.as_bytes());
    field(&mut data, "type", type_name.as_bytes());
    field(&mut data, "md5sum", b"*");
    record(
        &[
            ("op", &[0x07]),
            ("conn", &conn.to_le_bytes()),
            ("topic", topic.as_bytes()),
        ],
        &data,
    )
}

/// A message record on `conn` received at `t` seconds.
pub fn message(conn: u32, t: f64, body: &[u8]) -> Vec<u8> {
    let mut time = Vec::new();
    time.extend((t.floor() as u32).to_le_bytes());
    time.extend((((t - t.floor()) * 1e9).round() as u32).to_le_bytes());
    record(
        &[
            ("op", &[0x02]),
            ("conn", &conn.to_le_bytes()),
            ("time", &time),
        ],
        body,
    )
}

/// A chunk record holding `records`, compressed as `compression` says (`none`,
/// `bz2`), declaring `size` bytes decompressed (`None`: the true size).
pub fn chunk(compression: &str, records: &[u8], size: Option<u32>) -> Vec<u8> {
    let data = match compression {
        "bz2" => {
            use std::io::Write;
            let mut e = bzip2::write::BzEncoder::new(Vec::new(), bzip2::Compression::best());
            e.write_all(records).unwrap();
            e.finish().unwrap()
        }
        _ => records.to_vec(),
    };
    let size = size.unwrap_or(records.len() as u32);
    record(
        &[
            ("op", &[0x05]),
            ("compression", compression.as_bytes()),
            ("size", &size.to_le_bytes()),
        ],
        &data,
    )
}

/// A ROS 1 `std_msgs/Header` at `t` seconds.
fn header(out: &mut Vec<u8>, t: f64) {
    out.extend(0u32.to_le_bytes());
    out.extend((t.floor() as u32).to_le_bytes());
    out.extend((((t - t.floor()) * 1e9).round() as u32).to_le_bytes());
    out.extend(4u32.to_le_bytes());
    out.extend(b"base");
}

/// The fields of a LaserScan besides its ranges.
#[derive(Clone, Copy)]
pub struct Scan {
    pub angle_min: f32,
    pub angle_max: f32,
    pub angle_increment: f32,
    pub time_increment: f32,
    pub scan_time: f32,
    pub range_min: f32,
    pub range_max: f32,
}

/// An 11-ray scan over ±1 rad, 5 ms apart in a 0.1 s period, 0.02 to 4 m.
pub const SCAN: Scan = Scan {
    angle_min: -1.0,
    angle_max: 1.0,
    angle_increment: 0.2,
    time_increment: 0.0005,
    scan_time: 0.1,
    range_min: 0.02,
    range_max: 4.0,
};

/// A LaserScan body at `t` with `ranges`.
pub fn laser_scan(t: f64, s: &Scan, ranges: &[f32]) -> Vec<u8> {
    let mut b = Vec::new();
    header(&mut b, t);
    for v in [
        s.angle_min,
        s.angle_max,
        s.angle_increment,
        s.time_increment,
        s.scan_time,
        s.range_min,
        s.range_max,
    ] {
        b.extend(v.to_le_bytes());
    }
    b.extend((ranges.len() as u32).to_le_bytes());
    for r in ranges {
        b.extend(r.to_le_bytes());
    }
    b.extend(0u32.to_le_bytes());
    b
}

/// A JointState body at `t` with `names` and their `positions`.
pub fn joint_state(t: f64, names: &[&str], positions: &[f64]) -> Vec<u8> {
    let mut b = Vec::new();
    header(&mut b, t);
    b.extend((names.len() as u32).to_le_bytes());
    for n in names {
        b.extend((n.len() as u32).to_le_bytes());
        b.extend(n.as_bytes());
    }
    b.extend((positions.len() as u32).to_le_bytes());
    for p in positions {
        b.extend(p.to_le_bytes());
    }
    b.extend(0u32.to_le_bytes());
    b.extend(0u32.to_le_bytes());
    b
}

/// A small bag a robot could have recorded: `scans` 11-ray scans at 10 Hz (the one at
/// index `k` from `replace` replaced by its body), joint states at 50 Hz.
pub fn small_bag(scans: usize, replace: &dyn Fn(usize, f64) -> Option<Vec<u8>>) -> Vec<u8> {
    let mut b = bag_start();
    b.extend(connection(0, "/scan", "sensor_msgs/LaserScan"));
    b.extend(connection(1, "/joint_states", "sensor_msgs/JointState"));
    let names = ["wheel_left_joint", "wheel_right_joint"];
    for k in 0..scans * 5 {
        let t = 100.0 + k as f64 * 0.02;
        let a = k as f64 * 0.01;
        b.extend(message(1, t, &joint_state(t, &names, &[a, 1.1 * a])));
        if k % 5 == 0 {
            let i = k / 5;
            let body = replace(i, t).unwrap_or_else(|| {
                let ranges: Vec<f32> = (0..11).map(|r| 1.0 + 0.1 * r as f32).collect();
                laser_scan(t, &SCAN, &ranges)
            });
            b.extend(message(0, t, &body));
        }
    }
    b
}
