"""What ParaView sees in an XDMF file flexrom wrote: run by ParaView's own interpreter,
`pvpython pv_check.py FILE.xdmf [STEP] [PNG]` (test_paraview.py), never by pytest itself.

It opens the file with the reader ParaView's File → Open picks (`OpenDataFile`) and prints
one JSON line: the reader's name, the time steps it offers, the point and cell counts,
cell types, the point data arrays' names and components, and at instant STEP the points
and every array's values (for the test to compare with the HDF5 datasets). With PNG it also
renders instant STEP, coloured by the speed, into that file (this needs an X display:
Debian's ParaView renders through X, see docs/testing.md)."""

import json
import sys

from paraview import servermanager
from paraview.simple import (ColorBy, CreateRenderView, GetColorTransferFunction,
                             OpenDataFile, Render, ResetCamera, SaveScreenshot, Show)


def values(array):
    """A vtk array as a list of tuples (one per point)."""
    n, c = array.GetNumberOfTuples(), array.GetNumberOfComponents()
    return [list(array.GetTuple(i)) for i in range(n)] if c > 1 else [array.GetValue(i) for i in range(n)]


def describe(reader, step):
    """The reader's view of the file at instant `step` (an index into its time steps)."""
    times = list(reader.TimestepValues) if reader.TimestepValues else []
    reader.UpdatePipeline(times[step] if times else 0.0)
    grid = servermanager.Fetch(reader)
    points = grid.GetPoints()
    pd = grid.GetPointData()
    arrays = {pd.GetArrayName(i): pd.GetArray(i) for i in range(pd.GetNumberOfArrays())}
    return {
        "reader": reader.GetXMLName(),
        "class": grid.GetClassName(),
        "times": times,
        "n_points": grid.GetNumberOfPoints(),
        "n_cells": grid.GetNumberOfCells(),
        "cell_types": sorted({grid.GetCellType(i) for i in range(grid.GetNumberOfCells())}),
        "cell_sizes": sorted({grid.GetCell(i).GetNumberOfPoints() for i in range(grid.GetNumberOfCells())}),
        "points": [list(points.GetPoint(i)) for i in range(grid.GetNumberOfPoints())],
        "arrays": {name: {"components": a.GetNumberOfComponents(), "values": values(a)} for name, a in arrays.items()},
    }


def render(reader, time, png):
    """One frame at `time`: the centre lines, thick, coloured by the speed on its own range,
    on a white background (so that blank is one colour)."""
    view = CreateRenderView()
    view.ViewSize = [400, 300]
    view.UseColorPaletteForBackground = 0  # else the palette's grey-blue overrides it
    view.Background = [1.0, 1.0, 1.0]
    view.OrientationAxesVisibility = 0
    view.ViewTime = time
    shown = Show(reader, view)
    shown.LineWidth = 4.0
    ColorBy(shown, ("POINTS", "velocity", "Magnitude"))
    shown.RescaleTransferFunctionToDataRange(False, True)
    GetColorTransferFunction("velocity").ApplyPreset("Viridis (matplotlib)", True)
    ResetCamera(view)
    Render(view)
    SaveScreenshot(png, view, ImageResolution=[400, 300])


def main():
    path, step = sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 0
    reader = OpenDataFile(path)
    if reader is None:
        sys.exit(f"{path}: ParaView has no reader for this file")
    reader.UpdatePipelineInformation()
    seen = describe(reader, step)
    if len(sys.argv) > 3:
        render(reader, seen["times"][step] if seen["times"] else 0.0, sys.argv[3])
    print(json.dumps(seen))


main()
