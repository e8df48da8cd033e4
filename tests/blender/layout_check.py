# SPDX-License-Identifier: GPL-3.0-or-later
"""Which labels and buttons of a panel Blender would cut with "..." at a sidebar width.

A panel's draw() runs on a recording stand-in for bpy.types.UILayout that follows the
width each item gets: the panel's width (ui_text.label_width: the region less the tab
strip, the panel's margins and a label's padding), less a box's margins inside a box, the
factor of a split, an equal share of a row, less an icon; a UIList row gets the list's
width less its grip and scroll bar. Each text is measured with blf at the UI scale
(ui_text.text_width), as Blender draws it. Used headless (test_addon_ux.py) and in the
real window under Xvfb (viewport/screenshots.py, with the region's real width)."""

from __future__ import annotations

from dataclasses import dataclass, field
from types import SimpleNamespace

from mpeg4face_blender.ui import text as ui_text

LIST_MARGIN = 2 * 6 + 20  # a UIList's frame and its scroll bar, px at scale 1


@dataclass
class Item:
    text: str
    icon: bool
    share: "Layout"


@dataclass
class Layout:
    """Stands in for UILayout: `width` is the panel width this layout's items share."""

    context: object
    width: float
    boxes: int = 0
    items: list = field(default_factory=list)  # Item, or a sub-Layout
    in_row: bool = False
    factor: float | None = None  # a split's

    def _sub(self, width: float, boxes: int | None = None, in_row: bool = False) -> "Layout":
        sub = Layout(self.context, width, self.boxes if boxes is None else boxes, in_row=in_row)
        self.items.append(sub)
        return sub

    def _slot(self) -> float:
        """The width the next child of a split gets."""
        if self.factor is None:
            return self.width
        return self.width * (self.factor if not self.items else 1 - self.factor)

    # UILayout's item methods
    def label(self, text="", icon="NONE", **_):
        self.items.append(Item(text, icon not in ("NONE", ""), self))

    def operator(self, idname, text=None, icon="NONE", **_):
        if text is None:
            import bpy
            module, name = idname.split(".")
            text = getattr(getattr(bpy.ops, module), name).get_rna_type().name
        self.items.append(Item(text, icon not in ("NONE", ""), self))
        return SimpleNamespace()

    def prop(self, data, name, text=None, icon="NONE", **_):
        if text is None:
            text = data.bl_rna.properties[name].name if name in data.bl_rna.properties else name
        self.items.append(Item(text, icon not in ("NONE", ""), self))

    def template_list(self, list_type, *args, **kwargs):
        self.items.append(("list", list_type))

    def separator(self, **_):
        pass

    # sub-layouts
    def row(self, **_):
        return self._sub(self._slot(), in_row=True)

    def column(self, **_):
        return self._sub(self._slot())

    def box(self):
        return self._sub(self._slot(), self.boxes + 1)

    def split(self, factor=0.5, **_):
        sub = self._sub(self._slot())
        sub.factor = factor
        return sub

    def __setattr__(self, name, value):  # enabled, alert, operator_context, ...
        object.__setattr__(self, name, value)

    def cut(self) -> list[str]:
        """The texts wider than the width they get: "text (needs N px, has M px)"."""
        out = []
        # A row's items share its width equally (a split's children were sized above).
        children = [i for i in self.items if not (isinstance(i, tuple))]
        share = self.width / max(1, len(children)) if self.in_row else None
        for index, item in enumerate(self.items):
            if isinstance(item, Layout):
                out += item.cut()
            elif isinstance(item, Item) and item.text:
                width = share if share is not None else (
                    self.width if self.factor is None
                    else self.width * (self.factor if index == 0 else 1 - self.factor))
                has = self._text_width(width, item.icon)
                needs = ui_text.text_width(self.context, item.text)
                if needs > has + 0.5:
                    out.append(f"{item.text!r} (needs {needs:.0f} px, has {has:.0f} px)")
        return out

    def _text_width(self, width: float, icon: bool) -> float:
        s = ui_text.scale(self.context)
        return width - ui_text.PADDING * s - (ui_text.ICON * s if icon else 0)


def panel_width(context, region_width: float, boxes: int = 0) -> float:
    """The width a panel's top layout shares (before a label's padding and icon)."""
    s = ui_text.scale(context)
    return region_width - (ui_text.TABS + ui_text.PANEL) * s - boxes * ui_text.BOX * s


def cut_labels(panel, context, region_width: float) -> list[str]:
    """The texts of panel.draw() (and of its UIList rows, if any) cut at the width."""
    layout = Layout(context, panel_width(context, region_width))
    panel.draw(SimpleNamespace(layout=layout), context)
    return layout.cut()


def cut_list_rows(ui_list, context, region_width: float, data, propname: str) -> list[str]:
    """The texts of every row of a UIList cut at the width."""
    out = []
    width = panel_width(context, region_width) - LIST_MARGIN * ui_text.scale(context)
    for index, item in enumerate(getattr(data, propname)):
        layout = Layout(context, width)
        ui_list.draw_item(None, context, layout, data, item, 0, data, propname, index)
        out += layout.cut()
    return out
