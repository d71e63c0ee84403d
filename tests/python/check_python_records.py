"""Issue 18, item 16 (part): backlash.record() takes real numbers only.  A complex array — a
NumPy complex dtype, a Python complex, even with zero imaginary parts — is a ValueError that
names the column (float() would silently drop the imaginary part)."""
import numpy as np
import pytest

import backlash

T = np.arange(10.0)


@pytest.mark.parametrize("column", ["theta_out", "theta_motor", "theta_load", "drive"])
def test_item16_complex_numpy_array_refused(column):
    arrays = dict(t=T, theta_out=np.sin(T))
    arrays[column] = np.sin(T) * (1 + 2j)
    with pytest.raises(ValueError) as caught:
        backlash.record(**arrays)
    assert str(caught.value) == f"<arrays>: {column}: complex values, expected real numbers"


def test_item16_complex_values_refused_even_when_real_valued():
    with pytest.raises(ValueError, match="<arrays>: t: complex values"):
        backlash.record(T.astype(complex), np.sin(T))
    with pytest.raises(ValueError, match="<arrays>: theta_out: complex values"):
        backlash.record(T, [complex(v, 0) for v in np.sin(T)])


def test_item16_real_arrays_still_accepted():
    data = backlash.record(T, np.sin(T), drive=list(np.cos(T)))
    assert len(data) == 10
    assert list(data.theta_out) == list(np.sin(T))
