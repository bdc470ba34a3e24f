"""What every rockmech command script runs: document in, flow, files and drawings out."""

import glob
import os
from typing import Optional, Union

import Eto.Drawing
import Eto.Forms
import Rhino

from rhino_plugin.flows.analyse import AnalysisResult, analyse_flow
from rhino_plugin.flows.mechanisms import CommandResult, run_mechanism_command
from rhino_plugin.flows.prompter import Cancelled
from rhino_plugin.flows.retrofit import RETROFIT_LAYER, RetrofitFlowResult, retrofit_flow
from rhino_plugin.flows.search import SEARCH_LAYER, SearchFlowResult, search_flow
from rhino_plugin.rhino.docscene import DocScene
from rhino_plugin.rhino.draw import draw_marks
from rhino_plugin.rhino.prompts import RhinoPrompter
from shared_schema.errors import RockmechError

__all__ = ["SERVICE_URL_KEY", "run_analyse", "run_mechanism", "run_retrofit", "run_search"]

#: Document user text holding the REST service URL (set with Rhino's SetDocumentUserText).
SERVICE_URL_KEY = "rockmech_service_url"


def _saved_doc(command: str) -> Optional[Rhino.RhinoDoc]:
    doc = Rhino.RhinoDoc.ActiveDoc
    if doc is None or not doc.Path:
        Rhino.RhinoApp.WriteLine(
            f"{command}: save the model first; the spec and constants files are written "
            "next to the .3dm file. Nothing was written."
        )
        return None
    return doc


def run_mechanism(command: str) -> Optional[CommandResult]:
    """Run a mechanism command on the active document (``RM_SingleBlock``, ...)."""
    doc = _saved_doc(command)
    if doc is None:
        return None
    path = str(doc.Path)
    result = run_mechanism_command(
        command,
        RhinoPrompter(doc),
        DocScene.from_doc(doc),
        os.path.dirname(path),
        scene_name=os.path.basename(path),
    )
    if result is not None:
        n = draw_marks(doc, result.marks)
        Rhino.RhinoApp.WriteLine(f"{command}: {n} check objects on layer 'rockmech check'")
    return result


def _show_plot(result: Union[AnalysisResult, SearchFlowResult]) -> None:
    if not result.plot or not os.path.isfile(result.plot):
        return
    dialog = Eto.Forms.Dialog()
    dialog.Title = f"rockmech: {result.kind}"
    dialog.Resizable = True
    view = Eto.Forms.ImageView()
    view.Image = Eto.Drawing.Bitmap(result.plot)
    text = Eto.Forms.TextArea()
    text.ReadOnly = True
    text.Text = "\n".join(result.summary)
    layout = Eto.Forms.DynamicLayout()
    layout.Add(view, True, True)
    layout.Add(text, True, False)
    dialog.Content = layout
    dialog.ShowModal(Rhino.UI.RhinoEtoApp.MainWindow)  # pyright: ignore[reportAttributeAccessIssue]


def run_analyse() -> Optional[AnalysisResult]:
    """RM_Analyse on the active document's constants files (or any file)."""
    doc = _saved_doc("RM_Analyse")
    if doc is None:
        return None
    path = str(doc.Path)
    stem = os.path.splitext(os.path.basename(path))[0]
    folder = os.path.dirname(path)
    current = sorted(glob.glob(os.path.join(glob.escape(folder), f"{stem}.*.constants.json")))
    url = doc.Strings.GetValue(SERVICE_URL_KEY) or None
    result = analyse_flow(
        RhinoPrompter(doc),
        os.path.join(folder, f"{stem}.analysis"),
        current=current,
        service_url=url,
    )
    if result is not None:
        _show_plot(result)
    return result


def run_search() -> Optional[SearchFlowResult]:
    """RM_Search on the active document: search, write <model>.search/, draw, show."""
    doc = _saved_doc("RM_Search")
    if doc is None:
        return None
    path = str(doc.Path)
    result = search_flow(
        RhinoPrompter(doc),
        DocScene.from_doc(doc),
        os.path.dirname(path),
        scene_name=os.path.basename(path),
        scene_path=path,
        service_url=doc.Strings.GetValue(SERVICE_URL_KEY) or None,
    )
    if result is not None:
        n = draw_marks(doc, result.marks, layer=SEARCH_LAYER)
        Rhino.RhinoApp.WriteLine(f"RM_Search: {n} objects on layer '{SEARCH_LAYER}'")
        _show_plot(result)
    return result


def run_retrofit() -> Optional[RetrofitFlowResult]:
    """RM_Retrofit on the active document: retrofit, write <model>.retrofit/, draw the ties."""
    doc = _saved_doc("RM_Retrofit")
    if doc is None:
        return None
    path = str(doc.Path)
    ask = RhinoPrompter(doc)
    try:
        result = retrofit_flow(
            ask,
            os.path.dirname(path),
            stem=os.path.splitext(os.path.basename(path))[0],
            unit_scale=Rhino.RhinoMath.UnitScale(doc.ModelUnitSystem, Rhino.UnitSystem.Meters),
            service_url=doc.Strings.GetValue(SERVICE_URL_KEY) or None,
            scene=DocScene.from_doc(doc),
            scene_name=os.path.basename(path),
            scene_path=path,
        )
    except Cancelled:
        Rhino.RhinoApp.WriteLine("RM_Retrofit: cancelled.")
        return None
    except (RockmechError, ValueError) as exc:
        Rhino.RhinoApp.WriteLine(f"RM_Retrofit: {exc}")
        return None
    n = draw_marks(doc, result.marks, layer=RETROFIT_LAYER)
    Rhino.RhinoApp.WriteLine(f"RM_Retrofit: {n} objects on layer '{RETROFIT_LAYER}'")
    return result
