"""The golden recordings read with the MCAP project's own Python packages, not ours
(docs/recording-format.md, "Reading recordings elsewhere"): every message of every channel
decodes from the schemas stored in the file (ROS 2 `ros2msg`/CDR and Foxglove's protobuf),
each per-tick channel has one message a tick, and what the third-party decoders read is what
``nanohaptics.read_recording`` reads, to the bit.

The README's test command installs ``mcap``, ``mcap-ros2-support`` and
``mcap-protobuf-support``; a missing one fails here (no silent skips, docs/testing.md).
"""

from __future__ import annotations

import collections
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory as ProtobufDecoders
from mcap_ros2.decoder import DecoderFactory as Ros2Decoders

import nanohaptics as nh

ROOT = Path(__file__).resolve().parents[2]
GOLDENS = sorted((ROOT / "recordings").glob("*.mcap"))
PER_TICK = ("/device/input", "/world/state", "/haptic/force", "/loop/timing")


def test_there_are_goldens():
    assert {p.name for p in GOLDENS} >= {
        "wall.mcap", "brickworld.mcap", "brickworld_shipped.mcap", "nanoworld.mcap",
        "optical_tweezers.mcap"}


@pytest.mark.parametrize("path", GOLDENS, ids=[p.name for p in GOLDENS])
def test_every_channel_decodes_with_the_mcap_packages_as_nanohaptics_reads_it(path):
    ours = nh.read_recording(path)
    ticks = len(ours["tick"])
    counts = collections.Counter()
    encodings = {}
    position, device_force, world_force, tick = [], [], [], []
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[Ros2Decoders(), ProtobufDecoders()])
        for schema, channel, _message, msg in reader.iter_decoded_messages():
            counts[channel.topic] += 1
            encodings[channel.topic] = (schema.encoding, channel.message_encoding)
            if channel.topic == "/device/input":
                position.append(list(msg.position_m))
                tick.append(msg.tick)
            elif channel.topic == "/haptic/force":
                device_force.append(list(msg.device_force_n))
                world_force.append(list(msg.world_force_n))
    # Nine channels, each decoded from its own schema: seven ROS 2 messages, three Foxglove
    # protobuf ones.
    assert set(encodings) == {"/scene/description", *PER_TICK, "/events", "/foxglove/scene",
                              "/foxglove/tf", "/foxglove/log"}
    assert sorted(encodings.values()).count(("ros2msg", "cdr")) == 6
    assert sorted(encodings.values()).count(("protobuf", "protobuf")) == 3
    assert counts["/scene/description"] == 1
    for topic in PER_TICK:
        assert counts[topic] == ticks, topic
    # The display's channels at its own rate (50 Hz here): fewer than the ticks, at least one.
    assert 0 < counts["/foxglove/scene"] == counts["/foxglove/tf"] < ticks
    # What the MCAP packages read is what nanohaptics reads, bit for bit.
    assert np.array_equal(np.array(tick), ours["tick"])
    assert np.array_equal(np.array(position), ours["device_position_m"])
    assert np.array_equal(np.array(device_force), ours["device_force_n"])
    assert np.array_equal(np.array(world_force), ours["world_force_n"])
