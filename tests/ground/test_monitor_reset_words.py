"""The monitor's link table gives the reset cause in words (AVR MCUSR bits), not raw hex only."""
from fswkit.web.source import reset_words
from fswkit.ground import view


def test_reset_cause_in_words():
    assert reset_words(0x01) == "power-on"
    assert reset_words(0x08) == "watchdog"
    assert reset_words(0x06) == "external reset, brown-out"
    assert "none reported" in reset_words(0x00)
    assert view.reset_words is reset_words
