# SPDX-License-Identifier: Apache-2.0
"""The file flash of the native board: images outlive the process (doc/pgm.md)."""

import re

OLD = (14000, 3600000)
NEW = (15000, 7200000)
IMAGE = 32 + 600  # header and body of the image the test downloads
COMMIT = 16  # the commit record, the last bytes a switch writes
BOOT = re.compile(r"pgm_flash: boot: slot (\d) date (\d+) time (\d+) verified (\d) running (\d)")


def booted(result):
    """(slot, (date, time), verified, running) of the boot the run printed."""
    assert result.returncode == 0, result.stdout + result.stderr
    m = BOOT.search(result.stdout)
    assert m, result.stdout
    slot, date, time, verified, running = map(int, m.groups())
    return slot, (date, time), verified == 1, running == 1


def test_image_outlives_the_process(run, tmp_path):
    flash = str(tmp_path / "flash.bin")
    assert run("factory", flash).returncode == 0
    assert booted(run("boot", flash)) == (0, OLD, True, True)
    result = run("update", flash)
    assert "pgm_flash: start: 00000000" in result.stdout
    # The update's own process switched before it ended; a new process boots the new image.
    assert booted(result)[1] == OLD
    assert booted(run("boot", flash)) == (1, NEW, True, True)
    assert booted(run("boot", flash)) == (1, NEW, True, True), "and again"


def test_power_cut_at_byte_positions(run, tmp_path):
    """Cuts in the erase, in the download, in the commit record and after it."""
    total = IMAGE + COMMIT
    for cut in (0, 1, 31, 32, 33, IMAGE // 2, IMAGE - 1, IMAGE, IMAGE + 1, total - 1, total):
        flash = str(tmp_path / f"flash-{cut}.bin")
        assert run("factory", flash).returncode == 0
        result = run("update", flash, str(cut))
        assert result.returncode == 0, result.stdout
        assert ("power cut" in result.stdout) == (cut < total), (cut, result.stdout)
        after = booted(run("boot", flash))
        if cut < total:
            assert after == (0, OLD, True, True), (cut, after)
        else:
            assert after == (1, NEW, True, True), (cut, after)
        # The next process updates the device.
        assert "pgm_flash: start: 00000000" in run("update", flash).stdout, cut
        assert booted(run("boot", flash))[1:] == (NEW, True, True), cut


def test_an_empty_file_is_an_erased_flash(run, tmp_path):
    flash = tmp_path / "new.bin"
    result = run("boot", str(flash))
    assert result.returncode == 0
    assert "pgm_flash: boot: no valid program, 1F57h 02h" in result.stdout


def test_a_file_of_another_geometry_is_refused(run, tmp_path):
    flash = tmp_path / "big.bin"
    flash.write_bytes(b"\xff" * 4096)  # more than two slots of 1024 bytes
    result = run("boot", str(flash))
    assert result.returncode == 2
    assert "cannot open the flash file: -27" in result.stdout  # -EFBIG
    result = run("boot", str(tmp_path / "no-such-dir" / "flash.bin"))
    assert result.returncode == 2
    assert "cannot open the flash file: -2" in result.stdout  # -ENOENT


def test_bad_arguments_exit_2(run, tmp_path):
    assert run().returncode == 2
    assert run("erase", str(tmp_path / "f.bin")).returncode == 2
    assert run("update", str(tmp_path / "f.bin"), "x").returncode == 2
    assert run("boot", str(tmp_path / "f.bin"), "5").returncode == 2
