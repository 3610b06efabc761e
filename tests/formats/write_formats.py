#!/usr/bin/env python3
"""Writes one IMU session in the formats gravcal recognises (tests/formats_test.cc).

usage: write_formats.py <contract.csv from gravcal simulate> <out folder>

Writes, from the same samples (times rounded to whole nanoseconds, t = ns * 1e-9):
  contract.csv   the contract CSV t,ax,ay,az,gx,gy,gz
  euroc.csv      EuRoC / TUM-VI: #timestamp [ns],w_RS_S_x..z,a_RS_S_x..z
  session.db3    rosbag2 SQLite, sensor_msgs/msg/Imu in CDR (serialised here),
                 beside a /rosout topic of another type
  two_imus.db3   two sensor_msgs/msg/Imu topics (/imu0, /imu1 = the same samples)
  ros1_<c>.bag   ROS 1 bags written by the rosbag library, c = none, bz2, lz4;
                 only when `import rosbag` works (Debian python3-rosbag), else
                 a file ros1_absent.txt says why.
"""
import csv
import os
import sqlite3
import struct
import sys


def read_samples(path):
    with open(path) as f:
        rows = [r for r in csv.reader(f) if r and not r[0].startswith('#')]
    header = rows[0]
    col = {name: i for i, name in enumerate(header)}
    samples = []
    for r in rows[1:]:
        ns = round(float(r[col['t']]) * 1e9)
        accel = [float(r[col[k]]) for k in ('ax', 'ay', 'az')]
        gyro = [float(r[col[k]]) for k in ('gx', 'gy', 'gz')]
        samples.append((ns, accel, gyro))
    return samples


def cdr_imu(ns, accel, gyro, frame=b'imu_link'):
    """sensor_msgs/msg/Imu in little-endian CDR, alignment counted after the 4-byte header."""
    body = struct.pack('<iI', ns // 1000000000, ns % 1000000000)
    body += struct.pack('<I', len(frame) + 1) + frame + b'\0'
    body += b'\0' * ((8 - len(body) % 8) % 8)
    orientation = [0.0, 0.0, 0.0, 1.0]
    covariance = [0.0] * 9
    values = orientation + covariance + gyro + covariance + accel + covariance
    body += struct.pack('<37d', *values)
    return b'\x00\x01\x00\x00' + body


def write_db3(path, topics, samples):
    if os.path.exists(path):
        os.remove(path)
    db = sqlite3.connect(path)
    db.executescript("""
        CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);
        INSERT INTO schema VALUES (3, 'humble');
        CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL,
                              metadata TEXT NOT NULL);
        CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,
                            serialization_format TEXT NOT NULL,
                            offered_qos_profiles TEXT NOT NULL);
        CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL,
                              timestamp INTEGER NOT NULL, data BLOB NOT NULL);
        CREATE INDEX timestamp_idx ON messages (timestamp ASC);
    """)
    for i, (name, kind) in enumerate(topics, start=1):
        db.execute('INSERT INTO topics VALUES (?, ?, ?, ?, ?)', (i, name, kind, 'cdr', ''))
    rows = []
    for ns, accel, gyro in samples:
        for i, (name, kind) in enumerate(topics, start=1):
            if kind == 'sensor_msgs/msg/Imu':
                rows.append((i, ns + 1000, cdr_imu(ns, accel, gyro)))
            elif len(rows) % 100 == 0:
                rows.append((i, ns + 1000, b'\x00\x01\x00\x00log'))
    db.executemany('INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)', rows)
    db.commit()
    db.close()


def write_ros1(out, samples):
    try:
        import rosbag
        import rospy
        from sensor_msgs.msg import Imu
        from std_msgs.msg import String
    except ImportError as e:
        with open(os.path.join(out, 'ros1_absent.txt'), 'w') as f:
            f.write('rosbag (Debian python3-rosbag, python3-sensor-msgs) is absent: %s\n' % e)
        return
    for compression in ('none', 'bz2', 'lz4'):
        with rosbag.Bag(os.path.join(out, 'ros1_%s.bag' % compression), 'w',
                        compression=compression) as bag:
            for k, (ns, accel, gyro) in enumerate(samples):
                m = Imu()
                m.header.seq = k
                m.header.frame_id = 'imu_link'
                m.header.stamp = rospy.Time(ns // 1000000000, ns % 1000000000)
                m.orientation.w = 1.0
                m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z = gyro
                (m.linear_acceleration.x, m.linear_acceleration.y,
                 m.linear_acceleration.z) = accel
                received = rospy.Time(0, ns + 1000)
                bag.write('/imu/data', m, t=received)
                if k % 100 == 0:
                    bag.write('/status', String(data='ok'), t=received)


def main():
    source, out = sys.argv[1], sys.argv[2]
    samples = read_samples(source)
    with open(os.path.join(out, 'contract.csv'), 'w') as f:
        f.write('t,ax,ay,az,gx,gy,gz\n')
        for ns, a, g in samples:
            f.write(','.join(repr(x) for x in [ns * 1e-9] + a + g) + '\n')
    with open(os.path.join(out, 'euroc.csv'), 'w') as f:
        f.write('#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],'
                'a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\r\n')
        for ns, a, g in samples:
            f.write(','.join([str(ns)] + [repr(x) for x in g + a]) + '\r\n')
    write_db3(os.path.join(out, 'session.db3'),
              [('/rosout', 'rcl_interfaces/msg/Log'), ('/imu/data', 'sensor_msgs/msg/Imu')],
              samples)
    write_db3(os.path.join(out, 'two_imus.db3'),
              [('/imu0', 'sensor_msgs/msg/Imu'), ('/imu1', 'sensor_msgs/msg/Imu')], samples)
    write_ros1(out, samples)


if __name__ == '__main__':
    main()
