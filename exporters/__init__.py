"""Writers that sit on top of :mod:`planar`: GIF animation, DXF and SVG parts.

``planar`` never imports ``exporters``; the CLI does.
"""
