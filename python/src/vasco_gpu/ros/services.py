"""The node's services, a part of MappingNode (node.py) kept apart: ~/dynamic_map, ~/save_map,
~/save_session, ~/reset, ~/pause, and load_session's restore at configure. They use the node's
LiveMap, settings, publication and flush."""

from __future__ import annotations

from dataclasses import replace

from .. import _core
from .._errors import Error
from .session_file import load_session, save_session
from .settings import map_files

__all__ = ["NodeServices"]


class NodeServices:
    """The service callbacks of MappingNode (its live, settings, out, _flush, ...)."""

    def _dynamic_map(self, request, response):
        """GetMap, as slam_toolbox's dynamic_map: the map as of now, which is also the latest
        /map with every map_updates message since applied (a change not yet published is
        published first; one executor thread: no map is filled meanwhile). Before any map: an
        empty grid (info.width 0), logged."""
        self._publish_if_changed(now=True)
        if self.out.sent:
            response.map = self.out.current()
        else:
            self.get_logger().info("~/dynamic_map: no map yet (no scan mapped): an empty grid served")
        return response

    def _save_map(self, request, response):
        paths = map_files(self.settings.save_map_path)
        self._flush()
        m = self.live.finish()
        if not paths or m is None:
            response.success = False
            response.message = "save_map_path is empty: set it to the files to write" if not paths else \
                "no scan mapped yet: nothing to save"
            return response
        try:
            _core._write_maps(paths, m, self.settings.map_mode)
        except (OSError, ValueError, RuntimeError) as e:
            response.success, response.message = False, f"not saved: {e}"
            return response
        response.success, response.message = True, f"wrote {', '.join(paths)}"
        self.get_logger().info(response.message)
        return response

    def _load_session(self, path: str) -> None:
        """load_session: the saved scans mapped at their saved poses with the saved mapper
        parameters (the node's own apply again at their next change). SessionFileError naming
        the file and line, LiveMapError (max_memory, the mapper) fail the configure."""
        saved = load_session(path)
        self.live.restore(saved)
        if saved.params != self.settings.params:
            self.get_logger().warning(f"load_session {path}: the file's mapper parameters are used, not the node's "
                                      f"(a parameter change maps the scans again with the node's)")
        self.settings = replace(self.settings, params=saved.params)
        if len(saved):
            self._latest_stamp = int(max(saved.stamps))
        self.get_logger().info(f"load_session: {len(saved)} scans of {path} restored")

    def _save_session(self, request, response):
        """The stored scans, their stamps, mounts and current poses and the mapper parameters to
        session_path, one transaction. The grid is settled and published first, so that the last
        /map is the map a restart with load_session gives (a fresh map of the saved scans)."""
        path = self.settings.session_path
        if not path:
            response.success, response.message = False, "session_path is empty: set it to the file to write"
            return response
        self._flush()
        try:
            self.live.settle()
            self._publish_if_changed(settle=False)
            save_session(self.live, path)
        except (Error, OSError) as e:
            response.success, response.message = False, f"session not saved: {e}"
            self.get_logger().error(response.message)
            return response
        response.success, response.message = True, f"wrote {len(self.live)} scans to {path}"
        self.get_logger().info(response.message)
        return response

    def _reset(self, request, response):
        self._flush()  # the scans received before the reset are dropped with the others
        n = self._start_over()
        response.success, response.message = True, f"dropped {n} scans and the grid"
        self.get_logger().info(response.message)
        return response

    def _pause(self, request, response):
        self._flush()  # the scans received before the pause are mapped
        self.paused = bool(request.data)
        response.success = True
        response.message = "paused: new scans are not mapped" if self.paused else "mapping new scans"
        self.get_logger().info(response.message)
        return response
