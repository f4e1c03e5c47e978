# Error versus time per query, per model and budget, with FCL's and Bullet's points.
# Data: narrowphase_accuracy.dat, written by
#   ./build-narrow/bin/bench_narrowphase --accuracy=1000 --accuracy-data=docs/benchmarks/narrowphase_accuracy.dat
# Plot (from the repository root):
#   gnuplot docs/benchmarks/narrowphase_accuracy.gp
# The same plot against the independent volume-gradient reference (--reference=volume):
#   ./build-narrow/bin/bench_narrowphase --accuracy=300 --reference=volume --accuracy-data=docs/benchmarks/narrowphase_accuracy_volume.dat
#   gnuplot -e "data='docs/benchmarks/narrowphase_accuracy_volume.dat'; output='docs/benchmarks/narrowphase_accuracy_volume.png'; reference='the volume-gradient reference'; poses=300" docs/benchmarks/narrowphase_accuracy.gp
# Columns: mesh method budget time_us normal_deg_median normal_deg_p95 depth_err_median point_err_median
set terminal pngcairo size 1500,900 font "sans,10"
if (!exists("data")) data = "docs/benchmarks/narrowphase_accuracy.dat"
if (!exists("output")) output = "docs/benchmarks/narrowphase_accuracy.png"
if (!exists("reference")) reference = "the exact model"
if (!exists("poses")) poses = 1000
set output output
set multiplot layout 2,3 title sprintf("Narrow phase: median error against %s vs median CPU time per query (%d random touching poses per mesh; budgets 16, 64, 256, 1024, unlimited along each line)", reference, poses)
set logscale x
set grid
set key top right font ",9"
models = "dos average cfm contact-tree exact"
sel(m, name) = (strcol(1) eq m && strcol(2) eq name)
do for [m in "bunny fandisk box"] {
  set title m
  set xlabel "median CPU time per query (us)"
  set ylabel "normal error, median (deg)"
  plot for [name in models] data using (sel(m, name) ? $4 : 1/0):(sel(m, name) ? $5 : 1/0) with linespoints title name, \
       data using (sel(m, "FCL_OBBRSS") ? $4 : 1/0):(sel(m, "FCL_OBBRSS") ? $5 : 1/0) with points pt 7 ps 2 title "FCL", \
       data using (sel(m, "Bullet_GImpact") ? $4 : 1/0):(sel(m, "Bullet_GImpact") ? $5 : 1/0) with points pt 5 ps 2 title "Bullet"
}
do for [m in "bunny fandisk box"] {
  set title m
  set xlabel "median CPU time per query (us)"
  set ylabel "depth error, median (diagonals)"
  plot for [name in models] data using (sel(m, name) ? $4 : 1/0):(sel(m, name) ? $7 : 1/0) with linespoints title name, \
       data using (sel(m, "FCL_OBBRSS") ? $4 : 1/0):(sel(m, "FCL_OBBRSS") ? $7 : 1/0) with points pt 7 ps 2 title "FCL", \
       data using (sel(m, "Bullet_GImpact") ? $4 : 1/0):(sel(m, "Bullet_GImpact") ? $7 : 1/0) with points pt 5 ps 2 title "Bullet"
}
unset multiplot
