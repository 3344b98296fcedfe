"""Reading: PEER AT2, two-column text, units, and every bad-file case."""

from __future__ import annotations

import numpy as np
import obspy
import pytest

from harness.ground.records import (
    MIN_SAMPLES,
    STANDARD_GRAVITY,
    Quantity,
    RecordError,
    load_ground_motion,
    read_record,
    si_factor,
)

# ----------------------------------------------------------------- AT2 files


def _at2_values(n: int = 200, dt: float = 0.01) -> np.ndarray:
    t = np.arange(n) * dt
    return 0.05 * np.sin(2 * np.pi * 3.0 * t) * np.exp(-t)  # in g


def _write_at2(path, values, header_line, fmt="{:15.7E}", per_line=5, sep="",
               units_line="ACCELERATION TIME SERIES IN UNITS OF G"):
    lines = [
        "PEER NGA STRONG MOTION DATABASE RECORD",
        "SYNTHETIC TEST EVENT 01/01/00, TEST STATION, 090",
        units_line,
        header_line,
    ]
    for i in range(0, len(values), per_line):
        lines.append(sep.join(fmt.format(v) for v in values[i:i + per_line]))
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize(
    "header",
    [
        "NPTS=   200, DT=   .0100 SEC",  # NGA-West2 style
        "NPTS= 200 DT= 0.01 SEC",  # no comma
        "DT= .0100 SEC, NPTS=  200",  # swapped order
        "   200    0.0100    NPTS, DT",  # older NGA style
    ],
)
def test_at2_header_variants(tmp_path, header):
    vals = _at2_values()
    path = _write_at2(tmp_path / "rec.AT2", vals, header)
    rec = read_record(path)
    assert rec.quantity is Quantity.ACCELERATION
    assert rec.dt == pytest.approx(0.01)
    assert rec.npts == 200
    # values were printed with 8 significant digits, then converted from g
    np.testing.assert_allclose(rec.data, vals * STANDARD_GRAVITY, rtol=1e-7, atol=1e-9)
    assert "PEER" in rec.history[0]


def test_at2_fixed_width_values_without_separators(tmp_path):
    # Fortran fixed-width output lets negative numbers touch: "-.1234E-01-.5678E-02"
    vals = -np.abs(_at2_values()) - 1e-3
    path = _write_at2(tmp_path / "neg.at2", vals, "NPTS=   200, DT=   .0100 SEC",
                      fmt="{:11.4E}", sep="")
    assert "E-0" in path.read_text().splitlines()[4]
    rec = read_record(path)
    np.testing.assert_allclose(rec.data / STANDARD_GRAVITY, vals, rtol=1e-4)


def test_at2_without_unit_line_defaults_to_g_and_accepts_caller_units(tmp_path):
    vals = _at2_values()
    path = _write_at2(tmp_path / "nounit.at2", vals, "NPTS=200, DT=0.01", units_line="")
    rec = read_record(path)
    np.testing.assert_allclose(rec.data, vals * STANDARD_GRAVITY, rtol=1e-7, atol=1e-9)
    assert "convention" in rec.history[0]
    rec_cm = read_record(path, quantity="acceleration", unit="cm/s^2")
    np.testing.assert_allclose(rec_cm.data, vals * 0.01, rtol=1e-7, atol=1e-11)


def test_at2_header_units_conflicting_with_caller_is_an_error(tmp_path):
    path = _write_at2(tmp_path / "rec.at2", _at2_values(), "NPTS=200, DT=0.01")
    with pytest.raises(RecordError, match="header says acceleration in G"):
        read_record(path, quantity="acceleration", unit="m/s^2")
    rec = read_record(path, quantity="acceleration", unit="g")  # agreeing is fine
    assert rec.npts == 200


def test_peer_velocity_file(tmp_path):
    vals = _at2_values()
    path = _write_at2(tmp_path / "rec.VT2", vals, "NPTS=200, DT=0.01",
                      units_line="VELOCITY TIME SERIES IN UNITS OF CM/S")
    rec = read_record(path)
    assert rec.quantity is Quantity.VELOCITY
    np.testing.assert_allclose(rec.data, vals * 0.01, rtol=1e-7, atol=1e-11)


def test_at2_truncated(tmp_path):
    path = _write_at2(tmp_path / "short.at2", _at2_values()[:173], "NPTS=200, DT=0.01")
    with pytest.raises(RecordError, match=r"NPTS=200 but 173 samples.*truncated"):
        read_record(path)


def test_at2_without_header(tmp_path):
    path = tmp_path / "bad.at2"
    path.write_text("just some text\n1.0 2.0 3.0\n")
    with pytest.raises(RecordError, match="NPTS"):
        read_record(path)


def test_at2_with_garbage_among_samples(tmp_path):
    path = _write_at2(tmp_path / "junk.at2", _at2_values(), "NPTS=200, DT=0.01")
    text = path.read_text().splitlines()
    text[10] = text[10][:20] + "#@!" + text[10][23:]
    path.write_text("\n".join(text))
    with pytest.raises(RecordError, match=r"line 11: unexpected text"):
        read_record(path)


# ------------------------------------------------------------ two-column files


def _two_column(path, t, v, sep=",", header="time_s,acc"):
    rows = [header] if header else []
    rows += [f"{a:.6f}{sep}{b:.9e}" for a, b in zip(t, v)]
    path.write_text("\n".join(rows) + "\n")
    return path


def test_two_column_csv(tmp_path):
    t = 1.5 + np.arange(400) * 0.02
    v = np.sin(t)
    path = _two_column(tmp_path / "rec.csv", t, v)
    rec = read_record(path, quantity="acceleration", unit="cm/s^2")
    assert rec.dt == pytest.approx(0.02, rel=1e-9)
    assert rec.quantity is Quantity.ACCELERATION
    np.testing.assert_allclose(rec.data, v * 0.01, rtol=1e-8)


def test_two_column_whitespace_and_comments(tmp_path):
    t = np.arange(100) * 0.01
    path = tmp_path / "rec.txt"
    path.write_text("# velocity in mm/s\n\n" + "\n".join(
        f"  {a:.4f}\t {b:.6f}" for a, b in zip(t, np.cos(t))) + "\n")
    rec = read_record(path, quantity="vel", unit="mm/s")
    assert rec.quantity is Quantity.VELOCITY
    np.testing.assert_allclose(rec.data, np.cos(t) * 1e-3, rtol=1e-5)


def test_two_column_then_processed(tmp_path, analytic):
    path = _two_column(tmp_path / "rec.csv", analytic.t, analytic.a / STANDARD_GRAVITY)
    m = load_ground_motion(path, quantity="acceleration", unit="g")
    i0 = int(round(m.record_offset / m.dt))
    z = m.displacement[i0:i0 + analytic.t.size]
    assert np.max(np.abs(z - analytic.z)) < 2e-3 * np.max(np.abs(analytic.z))


def test_two_column_without_units_is_refused(tmp_path):
    path = _two_column(tmp_path / "rec.csv", np.arange(50) * 0.01, np.ones(50))
    with pytest.raises(RecordError, match="carries no units.*quantity=.*unit="):
        read_record(path)


def test_two_column_non_uniform_reports_max_deviation(tmp_path):
    t = np.arange(100) * 0.01
    t[40:] += 0.004  # a 4 ms jump: 40 % of the step
    path = _two_column(tmp_path / "jitter.csv", t, np.zeros(100))
    with pytest.raises(RecordError, match="not uniformly sampled") as info:
        read_record(path, quantity="acceleration", unit="m/s^2")
    msg = str(info.value)
    # grid through the first and last stamps: step 0.01 + 0.004/99, so row 41
    # (index 40) is off by 0.004·(1 - 40/99) = 2.38 ms, 23.7 % of the step
    assert "0.00238 s" in msg and "23.7% of dt" in msg and "row 41" in msg


def test_two_column_rounded_times_are_accepted(tmp_path):
    t = np.round(np.arange(300) * 0.005, 6)
    path = _two_column(tmp_path / "ok.csv", t, np.zeros(300))
    assert read_record(path, quantity="disp", unit="m").dt == pytest.approx(0.005)


def test_two_column_time_not_increasing(tmp_path):
    t = np.arange(50) * 0.01
    t[[10, 11]] = t[[11, 10]]
    path = _two_column(tmp_path / "swap.csv", t, np.zeros(50))
    with pytest.raises(RecordError, match="not strictly increasing"):
        read_record(path, quantity="acceleration", unit="g")


def test_two_column_three_columns(tmp_path):
    path = tmp_path / "three.csv"
    path.write_text("\n".join(f"{i * 0.01},{i},{i}" for i in range(50)))
    with pytest.raises(RecordError, match="expected two columns.*found 3"):
        read_record(path, quantity="acceleration", unit="g")


def test_two_column_text_in_the_middle(tmp_path):
    path = _two_column(tmp_path / "mid.csv", np.arange(50) * 0.01, np.zeros(50))
    lines = path.read_text().splitlines()
    lines[20] = "oops,here"
    path.write_text("\n".join(lines))
    with pytest.raises(RecordError, match="line 21: cannot read"):
        read_record(path, quantity="acceleration", unit="g")


def test_nan_samples(tmp_path):
    v = np.zeros(50)
    v[[7, 30]] = [np.nan, np.inf]
    path = _two_column(tmp_path / "nan.csv", np.arange(50) * 0.01, v)
    with pytest.raises(RecordError, match=r"2 of 50 samples are NaN or infinite \(first at sample 7\)"):
        read_record(path, quantity="acceleration", unit="g")


def test_nan_samples_in_seismic_format(tmp_path):
    data = np.zeros(100, dtype=np.float32)
    data[55] = np.nan
    path = tmp_path / "nan.sac"
    obspy.Trace(data, header={"delta": 0.01}).write(str(path), format="SAC")
    with pytest.raises(RecordError, match="NaN or infinite"):
        read_record(path, quantity="velocity", unit="m/s")


def test_too_short(tmp_path):
    path = _two_column(tmp_path / "short.csv", np.arange(5) * 0.01, np.zeros(5))
    with pytest.raises(RecordError, match=f"only 5 rows.*at least {MIN_SAMPLES}"):
        read_record(path, quantity="acceleration", unit="g")


# ------------------------------------------------------------ empty / corrupt


@pytest.mark.parametrize("name", ["empty.mseed", "empty.csv", "empty.at2", "empty.sac"])
def test_empty_file(tmp_path, name):
    path = tmp_path / name
    path.write_bytes(b"")
    with pytest.raises(RecordError, match="empty"):
        read_record(path, quantity="acceleration", unit="g")


def test_whitespace_only_text_is_empty(tmp_path):
    path = tmp_path / "blank.csv"
    path.write_text("\n   \n\n")
    with pytest.raises(RecordError, match="empty"):
        read_record(path, quantity="acceleration", unit="g")


def test_missing_file(tmp_path):
    with pytest.raises(RecordError, match="no such file"):
        read_record(tmp_path / "nope.mseed")


def test_corrupt_binary(tmp_path):
    path = tmp_path / "garbage.mseed"
    path.write_bytes(np.random.default_rng(0).integers(0, 256, 4000, dtype=np.uint8).tobytes())
    with pytest.raises(RecordError, match="cannot be read as any seismic format"):
        read_record(path)


def test_binary_file_named_csv(tmp_path):
    path = tmp_path / "garbage.csv"
    path.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(RecordError, match="binary data"):
        read_record(path, quantity="acceleration", unit="g")


def test_truncated_miniseed(tmp_path):
    full = tmp_path / "full.mseed"
    obspy.read().select(channel="EHZ").write(str(full), format="MSEED")
    cut = tmp_path / "cut.mseed"
    cut.write_bytes(full.read_bytes()[:5000])  # mid-record
    with pytest.raises(RecordError, match="damaged or truncated"):
        read_record(cut, quantity="velocity", unit="m/s")


def test_wrong_explicit_format(tmp_path):
    path = tmp_path / "rec.dat"
    path.write_text("0 1\n0.01 2\n")
    with pytest.raises(RecordError, match="cannot be read as format SAC"):
        read_record(path, format="SAC")


def test_gap_in_seismic_record(tmp_path):
    tr = obspy.read()[0]
    st = obspy.Stream([tr.slice(tr.stats.starttime, tr.stats.starttime + 10),
                       tr.slice(tr.stats.starttime + 12, tr.stats.endtime)])
    with pytest.raises(RecordError, match="has gaps"):
        read_record(st)


def test_ambiguous_channel_selection():
    st = obspy.read().select(component="[NE]")
    with pytest.raises(RecordError, match="holds 2 channels.*trace_id="):
        read_record(st)
    rec = read_record(st, trace_id="*EHN")
    assert rec.trace_id == "BW.RJOB..EHN"
    with pytest.raises(RecordError, match="matches 0 channels"):
        read_record(st, trace_id="*BHZ")


# ----------------------------------------------------------- quantities/units


@pytest.mark.parametrize(
    "quantity, unit, factor",
    [
        ("acceleration", "m/s^2", 1.0),
        ("acceleration", "m/s²", 1.0),
        ("ACC", "M/S**2", 1.0),
        ("acceleration", "cm/s/s", 0.01),
        ("acceleration", "Gal", 0.01),
        ("acceleration", "g", STANDARD_GRAVITY),
        ("acceleration", "G", STANDARD_GRAVITY),
        ("velocity", "cm/sec", 0.01),
        ("vel", "mm/s", 1e-3),
        ("velocity", "nm/s", 1e-9),
        ("displacement", "cm", 0.01),
        ("disp", "µm", 1e-6),
    ],
)
def test_unit_factors(quantity, unit, factor):
    assert si_factor(quantity, unit) == pytest.approx(factor, rel=1e-15)


@pytest.mark.parametrize(
    "quantity, unit, message",
    [
        ("jerk", "m/s^3", "unsupported quantity 'jerk'"),
        ("acceleration", "furlong/fortnight", "unsupported unit 'furlong/fortnight'"),
        ("velocity", "g", "unit 'g' is a unit of acceleration"),
        ("displacement", "m/s", "unit 'm/s' is a unit of velocity"),
    ],
)
def test_unsupported_quantities_and_units(tmp_path, quantity, unit, message):
    path = _two_column(tmp_path / "rec.csv", np.arange(50) * 0.01, np.zeros(50))
    with pytest.raises(RecordError, match=message):
        read_record(path, quantity=quantity, unit=unit)


def test_quantity_without_unit(tmp_path):
    path = _two_column(tmp_path / "rec.csv", np.arange(50) * 0.01, np.zeros(50))
    with pytest.raises(RecordError, match="together"):
        read_record(path, quantity="acceleration")


def test_record_error_is_a_value_error():
    assert issubclass(RecordError, ValueError)


def test_seismic_file_with_stated_units(tmp_path):
    data = np.sin(np.arange(500) * 0.05).astype(np.float32)
    path = tmp_path / "vel.sac"
    obspy.Trace(data, header={"delta": 0.01, "network": "XX", "station": "TST",
                              "channel": "HNZ"}).write(str(path), format="SAC")
    rec = read_record(path, quantity="velocity", unit="cm/s")
    assert rec.trace_id == "XX.TST..HNZ"
    assert rec.dt == pytest.approx(0.01)
    assert not rec.response_removed
    np.testing.assert_allclose(rec.data, data.astype(float) * 0.01, rtol=1e-7)
    with pytest.raises(RecordError, match="not both"):
        read_record(path, quantity="velocity", unit="cm/s", inventory=obspy.read_inventory())


def test_peer_quantity_conflict(tmp_path):
    path = _write_at2(tmp_path / "rec.at2", _at2_values(), "NPTS=200, DT=0.01",
                      units_line="ACCELERATION TIME SERIES")
    with pytest.raises(RecordError, match="header says acceleration"):
        read_record(path, quantity="velocity", unit="m/s")
