"""Production batches: many units, one machine's processes or a Dask cluster.

batch     the batch driver: units found, each calibrated, results and limits gathered
report    the fleet's HTML report
"""
