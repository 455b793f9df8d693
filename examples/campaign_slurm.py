"""Slurm campaign through dask-jobqueue (docs/sweeps.md): needs a Slurm cluster and `pip install dask-jobqueue`."""
# campaign_slurm.py — run on the login node (inside tmux/screen): it drives the sweep and writes the table
from dask.distributed import Client
from dask_jobqueue import SLURMCluster          # pip install dask-jobqueue
from particleShear.sweep import run_sweep

cluster = SLURMCluster(cores=8, processes=8, memory="16GB", walltime="08:00:00",
                       queue="standard", account="my_project",
                       job_script_prologue=["module load python/3.11", "source ~/venvs/ps/bin/activate"])
cluster.adapt(minimum_jobs=1, maximum_jobs=50)   # up to 400 single-core workers
with Client(cluster) as client:
    rows = run_sweep("examples/paper_campaign.toml", "/scratch/$USER/campaign",
                     executor=client.get_executor())
