#!/bin/bash
# Submit the render array and a merge job that starts when every task has succeeded.
set -euo pipefail
render=$(sbatch --parsable --export=ALL,SCENE="$1" render.sbatch)
sbatch --dependency=afterok:"${render%%;*}" merge.sbatch
