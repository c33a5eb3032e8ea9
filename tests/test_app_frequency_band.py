"""The one frequency-band widget of the Sweep and Infinite array tabs, typed into."""

import pytest

pytest.importorskip("PySide6")

from PySide6.QtCore import Qt  # noqa: E402
from PySide6.QtTest import QTest  # noqa: E402

from barymesh.app.panels.frequency_band import FrequencyBand  # noqa: E402


def _type(qtbot, field, text):
    field.selectAll()
    QTest.keyClicks(field, text)
    QTest.keyClick(field, Qt.Key.Key_Tab)


def test_typed_band_in_its_unit(qtbot):
    band = FrequencyBand("3", "12", "Sweep range")
    qtbot.addWidget(band)
    band.show()
    assert band.band() == (3e9, 12e9)
    _type(qtbot, band.start, "250")
    _type(qtbot, band.stop, "900")
    band.unit.setCurrentText("MHz")
    assert band.band() == (250e6, 900e6)
    _type(qtbot, band.stop, "100")
    with pytest.raises(ValueError, match="Sweep range 250 to 100 MHz: the end must be above"):
        band.band()
    _type(qtbot, band.stop, "lots")
    with pytest.raises(ValueError, match="'lots' is not a number"):
        band.band()


def test_set_band_shows_it_in_the_unit_of_its_top(qtbot):
    band = FrequencyBand("1", "2")
    qtbot.addWidget(band)
    band.set_band(800e6, 2.4e9)
    assert (band.start.text(), band.stop.text(), band.unit.currentText()) == ("0.8", "2.4", "GHz")
    assert band.band() == pytest.approx((800e6, 2.4e9), rel=1e-12)
