"""Widgets of the editor (views subscribe to the document)."""
