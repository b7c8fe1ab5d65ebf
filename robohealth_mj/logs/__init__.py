"""Controller logs in: a stock arm's own records (UR RTDE CSV, the voraus-AD parquet layout, any
table through a column map) read as GraphSamples with no ground truth, the joint channels only.
"""

from robohealth_mj.logs.convert import LOG_SUFFIXES, is_log, log_samples, log_sensing
from robohealth_mj.logs.maps import ColumnMap, load_map

__all__ = ["LOG_SUFFIXES", "ColumnMap", "is_log", "load_map", "log_samples", "log_sensing"]
