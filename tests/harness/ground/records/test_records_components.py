"""Three-component records: the vertical motion and the horizontal one along a slip azimuth,
each channel processed as a single channel is (obspy's example event BW.RJOB, counts,
with its example inventory)."""
import math

import numpy as np
import obspy
import pytest

from harness.ground.records import ProcessingSettings, RecordError, load_ground_motion, load_ground_motion_components

SETTINGS = ProcessingSettings(freqmin=1.0, freqmax=20.0)


@pytest.fixture(scope="module")
def event():
    return obspy.read(), obspy.read_inventory()


@pytest.fixture(scope="module")
def channels(event):
    stream, inventory = event
    return {axis: load_ground_motion(stream, SETTINGS, inventory=inventory, trace_id=f"BW.RJOB..EH{axis}")
            for axis in "ZNE"}


@pytest.mark.parametrize("azimuth", [0.0, 90.0, 30.0, -135.0])
def test_the_horizontal_motion_is_north_and_east_rotated_to_the_azimuth(event, channels, azimuth):
    """N cos(az) + E sin(az) of the channels processed one by one (the processing is
    linear: the rotation of the processed motions is the processed rotation), and the
    vertical motion is the vertical channel's own."""
    stream, inventory = event
    vertical, horizontal = load_ground_motion_components(stream, azimuth, SETTINGS, inventory=inventory)
    c, s = math.cos(math.radians(azimuth)), math.sin(math.radians(azimuth))
    for quantity in ("acceleration", "velocity", "displacement"):
        want = c * getattr(channels["N"], quantity) + s * getattr(channels["E"], quantity)
        np.testing.assert_allclose(getattr(horizontal, quantity), want, rtol=0,
                                   atol=1e-12 * np.max(np.abs(getattr(channels["N"], quantity))))
        np.testing.assert_array_equal(getattr(vertical, quantity), getattr(channels["Z"], quantity))
    np.testing.assert_array_equal(horizontal.time, vertical.time)
    assert f"azimuth {azimuth:g}" in horizontal.trace_id and "combined with" in horizontal.history[-1]


def test_channels_1_and_2_are_rotated_to_north_and_east_with_the_inventory(event, channels):
    """A sensor whose horizontals are named 1 and 2: with the inventory's orientations
    (here 1 = north, 2 = east) the result is the N/E record's."""
    stream, inventory = event
    renamed = stream.copy()
    for trace in renamed:
        trace.stats.channel = trace.stats.channel.replace("EHN", "EH1").replace("EHE", "EH2")
    renamed_inventory = inventory.select(station="RJOB").copy()
    for channel in (c for network in renamed_inventory for station in network for c in station):
        channel.code = channel.code.replace("EHN", "EH1").replace("EHE", "EH2")
    vertical, horizontal = load_ground_motion_components(renamed, 0.0, SETTINGS, inventory=renamed_inventory)
    np.testing.assert_allclose(horizontal.acceleration, channels["N"].acceleration, rtol=0,
                               atol=1e-9 * channels["N"].peak_acceleration)
    with pytest.raises(RecordError, match="need the inventory"):
        load_ground_motion_components(renamed, 0.0, SETTINGS, sensitivity=None)


def test_records_that_are_not_three_components_are_refused_saying_why(event):
    stream, inventory = event
    with pytest.raises(RecordError, match="no horizontal pair"):
        load_ground_motion_components(stream.select(channel="EHZ"), 0.0, SETTINGS, inventory=inventory)
    with pytest.raises(RecordError, match="one vertical channel"):
        load_ground_motion_components(stream.select(channel="EHN"), 0.0, SETTINGS, inventory=inventory)
    with pytest.raises(RecordError, match="azimuth"):
        load_ground_motion_components(stream, math.nan, SETTINGS, inventory=inventory)
