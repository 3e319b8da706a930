"""figures.save draws each format once (issue 47): the PNG it writes is the file matplotlib's
own ``savefig(bbox_inches="tight")`` writes after the same layout, and the PDF's page is the
same box within a fraction of a point."""

import re

import numpy as np
import pytest


def _figure():
    import matplotlib.pyplot as plt

    from opnav.core import figures

    with figures.style():
        fig, axes = plt.subplots(1, 2, figsize=(figures.PAGE_WIDTH_IN, 3.0), layout="constrained")
        t = np.linspace(1.0, 100.0, 50)
        for i, ax in enumerate(axes):
            ax.plot(t, t ** (i + 1), label=f"power {i + 1}")
            ax.set_yscale("log")
            figures.plain_log_labels(ax.yaxis)
            ax.set_xlabel("time (s)")
            ax.set_title(f"panel {i}", fontsize=8)
        h, lab = axes[0].get_legend_handles_labels()
        fig.legend(h, lab, loc="outside lower center", fontsize=6, ncol=2, frameon=False)
    return fig


def _media_box(pdf: bytes) -> np.ndarray:
    return np.array(re.search(rb"MediaBox \[ ([^\]]*) \]", pdf).group(1).split(), float)


@pytest.mark.slow  # ~1.5 CPU-s (issue 56: the default run <= 90 s)
def test_save_png_is_savefig_tight_and_pdf_page_within_a_point(tmp_path):
    from opnav.core import figures

    figures.save(_figure(), tmp_path / "new")
    ref = _figure()
    meta_png = {"Software": None}
    meta_pdf = {"CreationDate": None, "ModDate": None, "Producer": None, "Creator": None}
    kw = {"dpi": figures.SAVE_KW["dpi"], "bbox_inches": "tight", "pad_inches": figures.SAVE_KW["pad_inches"]}
    ref.draw_without_rendering()  # the layout once, as before issue 47, then tight per format
    ref.set_layout_engine(None)
    ref.savefig(tmp_path / "ref.png", format="png", metadata=meta_png, **kw)
    ref.savefig(tmp_path / "ref.pdf", format="pdf", metadata=meta_pdf, **kw)
    assert (tmp_path / "new.png").read_bytes() == (tmp_path / "ref.png").read_bytes()
    new_box, ref_box = _media_box((tmp_path / "new.pdf").read_bytes()), _media_box((tmp_path / "ref.pdf").read_bytes())
    assert np.all(np.abs(new_box - ref_box) < 1.0), (new_box, ref_box)  # points
