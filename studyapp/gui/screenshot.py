"""``studyapp gui --screenshot FILE``: the console, once it runs, saved as a PNG (for docs and checks).

The console bows the preview engine by itself (``PreviewBowing``); once the
scope shows a second and a half of it, the whole window is grabbed
(``QWidget.grab``: the widgets render themselves, so no window manager or
compositor is needed) and written atomically, its path printed, and the
application exits with 0.
"""

from PySide6.QtWidgets import QApplication

from studyapp.io.atomic import atomic_path
from studyapp.gui.preview_bowing import PreviewBowing


def save_widget(widget, path):
    """Render ``widget`` and write it to ``path`` as PNG, atomically; returns the path."""
    image = widget.grab()
    with atomic_path(path) as tmp:
        if not image.save(str(tmp), "PNG"):
            raise OSError(f"{path}: could not write the PNG")
    return path


class Screenshot(PreviewBowing):
    def __init__(self, console, path, **kwargs):
        super().__init__(console, **kwargs)
        self.path = path

    def ready(self):
        self.console.scope.redraw()
        save_widget(self.console, self.path)
        print(self.path)
        QApplication.instance().exit(0)
