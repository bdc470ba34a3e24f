"""The :class:`~rhino_plugin.flows.prompter.Prompter` of Rhino: command-line getters and Eto.

Escape at any getter, or Cancel in a dialog, raises
:class:`~rhino_plugin.flows.prompter.Cancelled`.
"""

import functools
import operator
from typing import Any, Dict, List, Optional, Sequence

import Eto.Drawing
import Eto.Forms
import Rhino
import Rhino.Input.Custom as ric
from Rhino.DocObjects import ObjectType
from Rhino.Input import GetResult

from rhino_plugin.flows.prompter import Cancelled, LineAnswer, Point

__all__ = ["RhinoPrompter"]


def _flags(*types: ObjectType) -> ObjectType:
    """OR of .NET flag values (the stubs do not declare ``|`` on enums; pythonnet does)."""
    return functools.reduce(operator.or_, types)


#: Object filters of the flows' object kinds.
FILTERS = {
    "solid": _flags(ObjectType.Brep, ObjectType.Extrusion, ObjectType.Mesh),
    "line": ObjectType.Curve,
    "plane": _flags(ObjectType.Surface, ObjectType.Brep, ObjectType.Curve, ObjectType.Mesh),
}


def _xyz(p: Any) -> Point:
    return (float(p.X), float(p.Y), float(p.Z))


class RhinoPrompter:
    """Answers a flow's questions with Rhino's command-line prompts and an Eto dialog."""

    def __init__(self, doc: Rhino.RhinoDoc) -> None:
        self.doc = doc

    def get_objects(
        self, prompt: str, kind: str = "solid", multiple: bool = True, optional: bool = False
    ) -> List[str]:
        """Select objects; Enter with nothing selected returns ``[]``."""
        go = ric.GetObject()
        go.SetCommandPrompt(prompt)
        go.GeometryFilter = FILTERS[kind]
        go.SubObjectSelect = False
        go.GroupSelect = True
        go.DeselectAllBeforePostSelect = True
        go.EnablePreSelect(False, True)
        go.AcceptNothing(True)
        res = go.GetMultiple(1, 0) if multiple else go.Get()
        if res == GetResult.Cancel:
            raise Cancelled()
        ids = []
        if res == GetResult.Object:
            ids = [str(go.Object(i).ObjectId) for i in range(go.ObjectCount)]
        self.doc.Objects.UnselectAll()
        return ids

    def get_number(
        self, prompt: str, default: Optional[float] = None, optional: bool = False
    ) -> Optional[float]:
        """Enter a number (Rhino's own parser refuses text that is not one)."""
        gn = ric.GetNumber()
        gn.SetCommandPrompt(prompt)
        if default is not None:
            gn.SetDefaultNumber(default)
        gn.AcceptNothing(optional or default is not None)
        res = gn.Get()
        if res == GetResult.Cancel:
            raise Cancelled()
        if res == GetResult.Nothing:
            return default
        return float(gn.Number())

    def get_line(self, prompt: str) -> LineAnswer:
        """Pick a line object, or choose Draw and draw one."""
        go = ric.GetObject()
        go.SetCommandPrompt(prompt)
        go.GeometryFilter = ObjectType.Curve
        go.SubObjectSelect = False
        go.EnablePreSelect(False, True)
        draw = go.AddOption("Draw")
        res = go.Get()
        if res == GetResult.Cancel:
            raise Cancelled()
        if res == GetResult.Option and go.OptionIndex() == draw:
            gl = ric.GetLine()
            gl.FirstPointPrompt = "Start of the line"
            gl.SecondPointPrompt = "End of the line"
            result, line = gl.Get()
            if result != Rhino.Commands.Result.Success:
                raise Cancelled()
            return (_xyz(line.From), _xyz(line.To))
        if res != GetResult.Object:
            raise Cancelled()
        ident = str(go.Object(0).ObjectId)
        self.doc.Objects.UnselectAll()
        return ident

    def get_points(self, prompt: str, count: int) -> List[Point]:
        """Pick ``count`` points."""
        points: List[Point] = []
        for k in range(count):
            gp = ric.GetPoint()
            gp.SetCommandPrompt(f"{prompt} ({k + 1} of {count})")
            if gp.Get() != GetResult.Point:
                raise Cancelled()
            points.append(_xyz(gp.Point()))
        return points

    def get_option(self, prompt: str, options: Sequence[str], default: int = 0) -> str:
        """Click an option; Enter takes the default."""
        go = ric.GetOption()
        go.SetCommandPrompt(prompt)
        index = {go.AddOption(name): name for name in options}
        go.SetDefaultString(options[default])
        go.AcceptNothing(True)
        res = go.Get()
        if res == GetResult.Cancel:
            raise Cancelled()
        if res == GetResult.Option:
            return index[go.OptionIndex()]
        if res == GetResult.Nothing:
            return options[default]
        raise Cancelled()

    def get_checkboxes(self, title: str, items: Sequence[str]) -> Dict[str, bool]:
        """Tick items in a modal Eto dialog; Cancel or closing raises Cancelled."""
        dialog = Eto.Forms.Dialog()
        dialog.Title = title
        dialog.Padding = Eto.Drawing.Padding(10)
        dialog.Resizable = False
        accepted = []

        def close(ok: bool) -> Any:
            def handler(sender: Any, e: Any) -> None:
                if ok:
                    accepted.append(True)
                dialog.Close()

            return handler

        layout = Eto.Forms.DynamicLayout()
        layout.Spacing = Eto.Drawing.Size(5, 5)
        boxes = {}
        for item in items:
            box = Eto.Forms.CheckBox()
            box.Text = item
            boxes[item] = box
            layout.Add(box, False, False)
        ok_button = Eto.Forms.Button()
        ok_button.Text = "OK"
        ok_button.Click += close(True)  # pyright: ignore[reportAttributeAccessIssue]  # event
        cancel_button = Eto.Forms.Button()
        cancel_button.Text = "Cancel"
        cancel_button.Click += close(False)  # pyright: ignore[reportAttributeAccessIssue]
        layout.Add(ok_button, False, False)
        layout.Add(cancel_button, False, False)
        dialog.DefaultButton = ok_button
        dialog.AbortButton = cancel_button
        dialog.Content = layout
        dialog.ShowModal(Rhino.UI.RhinoEtoApp.MainWindow)  # pyright: ignore[reportAttributeAccessIssue]
        if not accepted:
            raise Cancelled()
        return {item: bool(box.Checked) for item, box in boxes.items()}

    def get_file(self, prompt: str, extensions: Sequence[str], save: bool = False) -> str:
        """Choose a file in Rhino's file dialog."""
        patterns = ";".join(f"*{e}" for e in extensions)
        if save:
            sd = Rhino.UI.SaveFileDialog()
            sd.Title = prompt
            sd.Filter = f"{prompt} ({patterns})|{patterns}"
            if not sd.ShowSaveDialog():
                raise Cancelled()
            return str(sd.FileName)
        od = Rhino.UI.OpenFileDialog()
        od.Title = prompt
        od.Filter = f"{prompt} ({patterns})|{patterns}|All files (*.*)|*.*"
        if not od.ShowOpenDialog():
            raise Cancelled()
        return str(od.FileName)

    def message(self, text: str) -> None:
        """Write a line on Rhino's command line."""
        Rhino.RhinoApp.WriteLine(text)
