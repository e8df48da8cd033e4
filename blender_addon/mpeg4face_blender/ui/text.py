# SPDX-License-Identifier: GPL-3.0-or-later
"""Text that reads at the sidebar's width: labels wrapped to the width the panel gives them
(measured with blf at the UI scale, as Blender draws them) instead of cut with "...", and
a report's lines in a popup instead of inline.

The width a label gets is modelled on Blender's panel layout: the region's width less the
tab strip, the panel's margins and the label's own padding, less an icon when it has one,
less a box's margins inside a box (label_width). tests/blender/test_addon_ux.py checks every
label of the add-on's panels against the same model at the default width (229 px)."""

from __future__ import annotations

import textwrap
from collections.abc import Iterable

import blf
import bpy

from ..scene import compat

TABS = 20  # the sidebar's tab strip (px at UI scale 1)
PANEL = 2 * 12  # a panel's margins left and right
PADDING = 8  # a label's text inset
ICON = 20  # an icon before the text
BOX = 2 * 8  # a box's margins


def scale(context: bpy.types.Context) -> float:
    return context.preferences.system.ui_scale or context.preferences.view.ui_scale


def text_width(context: bpy.types.Context, text: str) -> float:
    """The width in pixels of `text` in the UI's label font."""
    blf.size(0, compat.label_points(context.preferences) * scale(context))
    return blf.dimensions(0, text)[0]


def label_width(context: bpy.types.Context, region_width: float | None = None,
                icon: bool = False, boxes: int = 0, factor: float = 1.0) -> float:
    """The pixels a label's text has in a panel of the region (context.region's width by
    default): `factor` of the panel's width (a split), inside `boxes` boxes."""
    s = scale(context)
    if region_width is None:
        region_width = context.region.width if context.region else 229 * s
    width = (region_width - (TABS + PANEL) * s - boxes * BOX * s) * factor
    return width - PADDING * s - (ICON * s if icon else 0)


def wrap(context: bpy.types.Context, text: str, width: float) -> list[str]:
    """`text` in lines of at most `width` pixels (at spaces and after commas; a word longer
    than a line is cut into pieces that fit)."""
    indent = text[:len(text) - len(text.lstrip(" "))]
    if indent:
        return [indent + line for line in wrap(context, text.lstrip(" "),
                                               width - text_width(context, indent))]
    words = text.split(" ")
    lines: list[str] = []
    line = ""
    for word in words:
        candidate = f"{line} {word}" if line else word
        if text_width(context, candidate) <= width:
            line = candidate
            continue
        if line:
            lines.append(line)
        while text_width(context, word) > width and len(word) > 1:
            cut = len(word) - 1
            while cut > 1 and text_width(context, word[:cut]) > width:
                cut -= 1
            lines.append(word[:cut])
            word = word[cut:]
        line = word
    if line or not lines:
        lines.append(line)
    return lines


def label(layout: bpy.types.UILayout, context: bpy.types.Context, text: str,
          icon: str = "NONE", boxes: int = 0, factor: float = 1.0) -> None:
    """A label wrapped to the panel's width (`factor` of it in a split); the lines after
    the first indented by the icon's width so they read as one message."""
    width = label_width(context, icon=icon != "NONE", boxes=boxes, factor=factor)
    col = layout.column(align=True)
    for i, line in enumerate(wrap(context, text, width)):
        col.label(text=line, icon=icon if i == 0 else ("BLANK1" if icon != "NONE" else "NONE"))


def popup(context: bpy.types.Context, title: str, lines: Iterable[str],
          icon: str = "INFO") -> None:
    """Lines in a popup at the mouse, each wrapped to about 70 characters; nothing in the
    background (there is no window)."""
    if bpy.app.background or not context.window_manager.windows:
        return
    lines = list(lines)

    def draw(menu: bpy.types.UIPopupMenu, _context: bpy.types.Context) -> None:
        col = menu.layout.column(align=True)
        for line in lines:
            for i, part in enumerate(textwrap.wrap(line, 70) or [""]):
                col.label(text=part if i == 0 else "    " + part)

    context.window_manager.popup_menu(draw, title=title, icon=icon)
