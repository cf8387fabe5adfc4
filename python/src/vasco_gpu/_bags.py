"""The console scripts' former module, kept while callers still import them from here: they are
vasco_gpu.bags.cli's bag2map_main and bag2carmen_main."""

from .bags.cli import bag2carmen_main, bag2map_main

__all__ = ["bag2carmen_main", "bag2map_main"]
