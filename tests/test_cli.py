import subprocess
import sys


def test_opnav_help_lists_purpose():
    proc = subprocess.run([sys.executable, "-m", "opnav.cli", "--help"], capture_output=True, text=True)
    assert proc.returncode == 0
    assert "snakemake --cores 2" in proc.stdout
