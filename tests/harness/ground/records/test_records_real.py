"""Ingest and response removal on real records bundled with obspy.

* ``obspy.read()`` without arguments: three components of station BW.RJOB
  (Jochberg, Bavarian network, 100 Hz), 2009-08-24 00:20:03 UTC, 30 s,
  shipped in ``obspy/core/data``. ``obspy.read_inventory()`` without
  arguments gives the station's real metadata (Erdbebendienst Bayern); the
  epoch from 2007-12-17 holds a 4-stage response, overall sensitivity
  2.5168e9 counts per m/s at 0.02 Hz. The record holds a local event: in
  2–20 Hz the ground velocity jumps ~50x above the noise 4.5 s in and decays
  over ~10 s of coda (checked below).
* ``IU_ULN_00_LH1_2015-07-18T02.mseed`` with ``IU_ULN_00_LH1.xml`` (obspy's
  core test data; the same pair obspy's own ``remove_response`` docs use):
  3 h of 1 Hz data from IU.ULN (Ulaanbaatar, STS-1), starting 2015-07-18
  02:27:33 UTC, the origin time of the Mw 7.0 Santa Cruz Islands
  earthquake, ~78° away. P arrives ~12 min in (iasp91: 716 s) and the
  surface waves peak ~33 min in, as checked below.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import obspy
import pytest

from harness.ground.records import (
    ProcessingSettings,
    Quantity,
    RecordError,
    ResponseSettings,
    process_record,
    read_record,
)

RJOB_SENSITIVITY = 2.5168e9  # counts per m/s, from the example inventory
ULN_SENSITIVITY = 3.39571e9  # counts per m/s at 0.05 Hz, from IU_ULN_00_LH1.xml

_OBSPY_DATA = Path(obspy.__file__).parent / "core" / "tests" / "data"
ULN_RECORD = _OBSPY_DATA / "IU_ULN_00_LH1_2015-07-18T02.mseed"
ULN_INVENTORY = _OBSPY_DATA / "IU_ULN_00_LH1.xml"
needs_uln = pytest.mark.skipif(
    not (ULN_RECORD.is_file() and ULN_INVENTORY.is_file()),
    reason="obspy installed without its core test data",
)


@pytest.fixture(scope="module")
def rjob_inventory():
    return obspy.read_inventory()


@pytest.fixture(scope="module")
def rjob_file(tmp_path_factory):
    """The example stream as a MiniSEED file (no response inside, as usual)."""
    st = obspy.read()
    for tr in st:
        del tr.stats.response
    path = tmp_path_factory.mktemp("rjob") / "BW.RJOB.2009-08-24.mseed"
    st.write(str(path), format="MSEED")
    return path


def test_rjob_counts_without_response_are_refused(rjob_file):
    with pytest.raises(RecordError, match="no instrument response and no stated units"):
        read_record(rjob_file)


def test_rjob_response_removal(rjob_file, rjob_inventory):
    raw = obspy.read(str(rjob_file)).select(channel="EHZ")[0].data.astype(float)
    rec = read_record(rjob_file, inventory=rjob_inventory)
    assert rec.trace_id == "BW.RJOB..EHZ"  # the vertical is the default
    assert rec.quantity is Quantity.VELOCITY  # native output of a seismometer
    assert rec.response_removed
    assert rec.start_time.startswith("2009-08-24T00:20:03")
    pgv = np.max(np.abs(rec.data))
    # a small local event: sub-micrometre per second, far from counts (~1e3)
    assert 1e-8 < pgv < 1e-5
    # removing the response divides by the instrument gain (2.5e9 counts/(m/s))
    gain = np.max(np.abs(raw - raw.mean())) / pgv
    assert 0.5 * RJOB_SENSITIVITY < gain < 2.0 * RJOB_SENSITIVITY


def test_rjob_attached_response_gives_the_same_record(rjob_file, rjob_inventory):
    from_file = read_record(rjob_file, inventory=rjob_inventory)
    from_stream = read_record(obspy.read())  # example stream carries its response
    np.testing.assert_allclose(from_stream.data, from_file.data, rtol=0, atol=1e-15)


def test_rjob_holds_a_seismic_event(rjob_file, rjob_inventory):
    rec = read_record(rjob_file, inventory=rjob_inventory)
    m = process_record(rec, ProcessingSettings(freqmin=2.0, freqmax=20.0))
    i0 = int(round(m.record_offset / m.dt))
    v = np.abs(m.velocity[i0:i0 + rec.npts])
    noise = v[: int(4.0 / m.dt)].max()  # before the onset at ~4.5 s
    assert v.max() > 10 * noise
    assert 4.5 < np.argmax(v) * m.dt < 10.0


def test_rjob_acc_and_vel_outputs_agree(rjob_file, rjob_inventory):
    settings = ProcessingSettings(freqmin=0.5, freqmax=25.0)
    pre_filt = (0.2, 0.4, 30.0, 40.0)
    vel = process_record(read_record(rjob_file, inventory=rjob_inventory,
                                     response=ResponseSettings(pre_filt=pre_filt)), settings)
    acc = process_record(read_record(rjob_file, inventory=rjob_inventory,
                                     response=ResponseSettings(output="ACC", water_level=None,
                                                               pre_filt=pre_filt)), settings)
    assert acc.peak_velocity == pytest.approx(vel.peak_velocity, rel=0.02)
    assert acc.peak_acceleration == pytest.approx(vel.peak_acceleration, rel=0.02)
    # physically plausible: PGA ~ 2π f PGV for a few-Hz local event
    ratio = vel.peak_acceleration / vel.peak_velocity / (2 * np.pi)
    assert 1.0 < ratio < 25.0
    # processed record ends at rest
    assert abs(vel.displacement[-1]) < 1e-12 * vel.peak_displacement


@needs_uln
def test_uln_teleseism_response_removal():
    rec = read_record(ULN_RECORD, inventory=ULN_INVENTORY)
    assert rec.trace_id == "IU.ULN.00.LH1"
    assert rec.quantity is Quantity.VELOCITY
    # gain check in the flat band of the STS-1: filter counts and velocity alike
    raw = obspy.read(str(ULN_RECORD))[0]
    phys = obspy.Trace(np.array(rec.data), header={"delta": rec.dt})
    for tr in (raw, phys):
        tr.detrend("linear")
        tr.taper(0.05)
        tr.filter("bandpass", freqmin=0.02, freqmax=0.1, zerophase=True)
    gain = np.max(np.abs(raw.data)) / np.max(np.abs(phys.data))
    assert gain == pytest.approx(ULN_SENSITIVITY, rel=0.05)

    m = process_record(rec, ProcessingSettings(freqmin=0.01, freqmax=0.3))
    # Mw 7 at ~78°: tens of µm/s and a fraction of a millimetre
    assert 3e-6 < m.peak_velocity < 3e-4
    assert 3e-5 < m.peak_displacement < 3e-3
    # surface waves (group velocity 3-4.2 km/s over ~8600 km) carry the peak
    i0 = int(round(m.record_offset / m.dt))
    t_peak = (np.argmax(np.abs(m.velocity)) - i0) * m.dt
    assert 1500.0 < t_peak < 3000.0
    # P at ~716 s: quiet before 600 s compared with after 700 s
    v = np.abs(m.velocity[i0:])
    assert v[700:1300].max() > 3 * v[:600].max()


@needs_uln
def test_uln_all_output_quantities_process_to_the_same_motion():
    settings = ProcessingSettings(freqmin=0.01, freqmax=0.3)
    motions = {
        out: process_record(
            read_record(ULN_RECORD, inventory=ULN_INVENTORY,
                        response=ResponseSettings(output=out, water_level=None,
                                                  pre_filt=(0.002, 0.005, 0.4, 0.45))),
            settings)
        for out in ("ACC", "VEL", "DISP")
    }
    ref = motions["VEL"]
    for out in ("ACC", "DISP"):
        m = motions[out]
        for name in ("acceleration", "velocity", "displacement"):
            err = np.max(np.abs(getattr(m, name) - getattr(ref, name)))
            assert err < 2e-3 * np.max(np.abs(getattr(ref, name))), (out, name)
