#!/bin/bash
# A design-space map of case V on a Slurm cluster: `backlash map` under MPI (docs/design.md,
# "Design-space maps").  One rank per node, its threads on the node's cores; rank 0 writes
# the folder.  Submit: sbatch examples/map-slurm.sh; after a time-out or a preemption the
# same script with RESUME=--resume continues from the last completed block.
#SBATCH --job-name=backlash-map
#SBATCH --nodes=100
#SBATCH --ntasks-per-node=1
#SBATCH --cpus-per-task=32
#SBATCH --time=12:00:00
#SBATCH --signal=B:TERM@120          # SIGTERM two minutes before the limit: stop at a block end
#SBATCH --output=backlash-map-%j.log

set -euo pipefail
module load openmpi 2>/dev/null || true   # site-specific; Debian: apt-get install openmpi-bin

# srun starts the ranks (PMI/PMIx); `mpirun -n $SLURM_NTASKS` works as well.
srun --mpi=pmix backlash map V \
  --vary JL_over_Jm=0.1:4:1000 --vary FL_over_F=0:1:1000 --vary K=0.5:2:1000 \
  --threads "$SLURM_CPUS_PER_TASK" --no-figures \
  --out "$SLURM_SUBMIT_DIR/map-V" ${RESUME:-} &
wait $!      # the batch shell forwards the SIGTERM to srun while it waits
