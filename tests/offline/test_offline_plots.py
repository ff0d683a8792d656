"""Offline plots: one readable PNG per friction for the phase diagrams and the profiles."""

from eoam_sumo.offline.tables import default_tables_dir
from eoam_sumo.plotting.offline_plots import plot_accel_profiles, plot_phase_diagrams

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def test_phase_diagrams_and_accel_profiles_are_written(tmp_path):
    phase = plot_phase_diagrams(default_tables_dir(), tmp_path / "a")
    accel = plot_accel_profiles(default_tables_dir(), tmp_path / "b")
    assert [p.name for p in phase] == [
        f"phase_diagram_mu{m}.png" for m in ("1.00", "0.70", "0.30", "0.10")
    ]
    assert [p.name for p in accel] == [
        f"accel_profiles_mu{m}.png" for m in ("1.00", "0.70", "0.30", "0.10")
    ]
    for p in phase + accel:
        data = p.read_bytes()
        assert data.startswith(PNG_MAGIC) and len(data) > 20000
