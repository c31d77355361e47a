"""Old RASP files, written by DOS tools, end with a Ctrl-Z (0x1A, DOS's
end-of-file mark); such a file was refused with "a motor's header has 7
fields ...; this one has 1" and "motor  has no thrust points" at its last
line, naming a character nobody can see. Any other control character in a
line was likewise taken into a name or a number and shown as is. A file
saved as UTF-16 (Windows Notepad's "Unicode") was "a binary file".

Now the text of a motor file ends at a DOS end-of-file mark that only
blank text follows, as DOS read it; a control character anywhere else is
an error at its column naming it (U+0007), the line otherwise not read;
and a UTF-16 file is said to be one, with what to save it as."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES

from fswkit.plant.motor import EngError, load, parse

G80T = (EXAMPLES / "rocket" / "motors" / "G80T.eng").read_text()


@pytest.mark.parametrize("tail", ["\x1a", "\x1a\x1a", "\x1a\r\n", "\r\n\x1a"])
def test_a_dos_end_of_file_mark_ends_the_text(tmp_path, tail):
    f = tmp_path / "g.eng"
    f.write_bytes((G80T.replace("\n", "\r\n") + tail).encode())
    (m,) = load(str(f))
    assert m.name == "G80T" and m.total_impulse == pytest.approx(118.56)


@pytest.mark.parametrize("text, line, col, char", [
    (G80T + "\x1a" + G80T, 15, 1, "U+001A"),  # a mark with a motor after it: not the end
    (G80T.replace("0.30  100.0", "0.30\x07 100.0"), 8, 8, "U+0007"),
    (G80T.replace("G80T 29", "G8\x000T 29"), 5, 3, "U+0000"),
])
def test_a_control_character_is_named_at_its_column(text, line, col, char):
    with pytest.raises(EngError) as e:
        parse(text, "m.eng")
    first = e.value.errors[0]
    assert first == f"m.eng:{line}:{col}: a control character ({char}) in the text: delete it (a motor file is " \
                    "plain text)", e.value.errors


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-be"])
def test_a_utf16_file_is_said_to_be_one(tmp_path, encoding):
    f = tmp_path / "g.eng"
    f.write_bytes(("\ufeff" if encoding.endswith("be") else "").encode(encoding) + G80T.encode(encoding))
    with pytest.raises(EngError) as e:
        load(str(f))
    assert e.value.errors == [f"{f}:1:1: UTF-16 text (Notepad's \"Unicode\"): save the motor file as UTF-8 or "
                              "ASCII text"]
