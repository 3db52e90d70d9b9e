#!/usr/bin/env python3
"""Makes assets/fonts/ubuntu-light-unhinted.ttf from egui's Ubuntu-Light.ttf: every glyph and
layout feature kept, the TrueType hinting programs and the device tables (hdmx, VDMX, LTSH)
dropped — egui rasterises without them — which takes the web build's font from 171 kB to
66 kB gzipped. As the Ubuntu Font Licence 1.0 (2c) asks of a Modified Version that is not
Substantially Changed, it is renamed "Ubuntu Light derivative cloudsketch".

Usage: python3 scripts/subset_font.py PATH/TO/Ubuntu-Light.ttf  (needs fonttools)
"""
import sys

from fontTools import subset
from fontTools.ttLib import TTFont

src = sys.argv[1]
out = "assets/fonts/ubuntu-light-unhinted.ttf"
options = subset.Options()
options.hinting = False
options.drop_tables += ["hdmx", "VDMX", "LTSH"]
options.layout_features = ["*"]
options.name_IDs = ["*"]
options.name_languages = ["*"]
options.notdef_outline = True
font = TTFont(src)
subsetter = subset.Subsetter(options)
subsetter.populate(unicodes=font.getBestCmap().keys())
subsetter.subset(font)
names = font["name"]
for record in names.names:
    text = record.toUnicode()
    if record.nameID in (1, 4, 16):
        record.string = text.replace("Ubuntu Light", "Ubuntu Light derivative cloudsketch") if "Ubuntu Light" in text else text + " derivative cloudsketch"
    elif record.nameID == 6:
        record.string = text.replace("-", "") + "derivativecloudsketch"
font.save(out)
print(out)
