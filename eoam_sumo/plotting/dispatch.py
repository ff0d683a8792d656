"""``eoam-sumo plot FOLDER``: the plots that fit the kind of output folder given."""

from __future__ import annotations

from pathlib import Path

from eoam_sumo.errors import InputError


def plot_folder(folder: Path, out_dir: Path) -> list[Path]:
    """Plot a run folder (summary.json), a batch folder (results.csv: a matrix's or an
    .xosc's variations) or a tables folder (phase_boundaries.csv) into ``out_dir``; return the
    PNGs written."""
    folder, out_dir = Path(folder), Path(out_dir)
    if (folder / "results.csv").is_file():
        from eoam_sumo.plotting.xosc_batch_plots import is_xosc_results, plot_xosc_batch

        if is_xosc_results(folder / "results.csv"):
            return plot_xosc_batch(folder, out_dir)
        from eoam_sumo.plotting.batch_plots import plot_batch

        return plot_batch(folder, out_dir)
    if (folder / "summary.json").is_file():
        from eoam_sumo.plotting.run_plots import plot_run

        if not any((folder / f"timeseries.{k}").is_file() for k in ("csv", "parquet")):
            raise InputError(
                f"{folder}: has summary.json but no time series (timeseries.csv or .parquet: "
                "a run with --timeseries none has nothing to plot)"
            )
        from eoam_sumo.plotting.traffic_plots import plot_traffic

        return [*plot_run(folder, out_dir), plot_traffic(folder, out_dir)]
    if (folder / "phase_boundaries.csv").is_file():
        from eoam_sumo.offline.tables import NPZ_NAME
        from eoam_sumo.plotting.offline_plots import plot_accel_profiles, plot_phase_diagrams

        if not (folder / NPZ_NAME).is_file():
            raise InputError(f"{folder}: has phase_boundaries.csv but no {NPZ_NAME}")

        return [
            *_paths(plot_phase_diagrams(folder, out_dir)),
            *_paths(plot_accel_profiles(folder, out_dir)),
        ]
    raise InputError(
        f"{folder}: not a run (summary.json), batch (results.csv) or tables "
        "(phase_boundaries.csv) folder"
    )


def _paths(result) -> list[Path]:
    """A plot function's return: one path or a list of paths."""
    if isinstance(result, (str, Path)):
        return [Path(result)]
    return [Path(p) for p in result]
