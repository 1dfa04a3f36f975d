import base64
import io
import re

import numpy as np
import pandas as pd
import pytest

from lib.figures import animation
from lib.tracking import runs as tracking
from lib.params import Body, Gains


def test_animation_html_is_self_contained_and_small():
    res = tracking.run(Body(), Gains(), "circle", 2.0, np.pi / 4, 0.25, samples_per_period=40)
    out = animation.animate(res, Body(), n_frames=5)
    assert "http://" not in out and "https://" not in out
    assert len(re.findall(r"data:image/png;base64", out)) == 5 or out.count("frames[") >= 5
    assert len(out) < 500_000


def test_csv_link_round_trips_the_data():
    df = pd.DataFrame({"t_s": [0.0, 0.5], "x_m": [1.0, 1.25]})
    link = animation.csv_link(df, "d.csv")
    data = re.search(r"base64,([A-Za-z0-9+/=]+)", link).group(1)
    back = pd.read_csv(io.StringIO(base64.b64decode(data).decode()))
    pd.testing.assert_frame_equal(back, df)
    assert 'download="d.csv"' in link


def test_bad_media_arguments_are_rejected():
    with pytest.raises(ValueError, match=".csv"):
        animation.csv_link(pd.DataFrame({"a": [1]}), "d.txt")
    res = tracking.run(Body(), Gains(), "circle", 2.0, np.pi / 4, 0.1, samples_per_period=40)
    with pytest.raises(ValueError, match="n_frames"):
        animation.animate(res, Body(), n_frames=1)
