"""The HTML page of `fivebar view`: a template, style and script shipped as package data, filled
with the trees' B/W/G bodies (page.py)."""
