"""BlockChain catalogues read into pandas and obspy (``harness.chain.catalog``)."""
import math

import pytest

from harness.chain.catalog import CatalogError, read_catalog, to_obspy
from vibroblock.chain.catalog import CatalogFile, magnitude

EVENTS = [(10.0, 12.5, 0, 3, 100.0, 2.0), (40.0, 40.5, 5, 1, 1e-3, 0.4), (90.0, 95.0, 2, 16, 1e4, 3.1)]


@pytest.fixture
def catalog(tmp_path):
    path = tmp_path / "events.csv"
    file = CatalogFile(path)
    file.begin("event start: a block's |vx| > v_start = 0.3; end: every |vx| < v_stop = 0.1")
    file.append(EVENTS[:2])  # written as events close, in two flushes
    file.append(EVENTS[2:])
    return path


def test_the_file_reads_back_every_event_with_its_magnitude_and_thresholds(catalog):
    frame = read_catalog(catalog)
    assert frame["t_start"].tolist() == [e[0] for e in EVENTS]
    assert frame["first_block"].tolist() == [e[2] + 1 for e in EVENTS]  # 1-based in the file
    assert frame["potency"].tolist() == [e[4] for e in EVENTS]
    assert frame["magnitude"].tolist() == pytest.approx([2.0 / 3.0 * math.log10(e[4]) for e in EVENTS])
    assert "v_start = 0.3" in frame.attrs["thresholds"]


def test_the_obspy_catalog_has_one_event_per_row_at_its_time_and_magnitude(catalog):
    events = to_obspy(read_catalog(catalog), origin="2020-01-01T00:00:00", seconds_per_tau=0.5)
    assert len(events) == 3
    first = events[0]
    assert str(first.origins[0].time) == "2020-01-01T00:00:05.000000Z"  # t_start 10 tau_0 x 0.5 s
    assert first.magnitudes[0].mag == pytest.approx(magnitude(100.0)) and first.magnitudes[0].magnitude_type == "Mp"
    assert "v_stop = 0.1" in events.description


def test_a_file_that_is_not_a_catalogue_is_refused_in_one_line(tmp_path):
    other = tmp_path / "other.csv"
    other.write_text("a,b\n1,2\n")
    with pytest.raises(CatalogError, match="not a BlockChain event catalogue"):
        read_catalog(other)
    with pytest.raises(CatalogError, match="cannot read"):
        read_catalog(tmp_path / "missing.csv")


def test_no_potency_has_no_magnitude():
    assert math.isnan(magnitude(0.0)) and magnitude(10.0) == pytest.approx(2.0 / 3.0)
