set datafile separator ','
set terminal pngcairo size 800,520
set output 'ensemble-sweep.png'
set grid
set multiplot layout 2,1 title 'double pendulum released from rest with th2 = 0: 97 runs of eom-ensemble --sweep th1=0.1:2.5:97'
set ylabel 'th2 at t = 10 s (rad)'
unset xlabel
plot 'ensemble-sweep.csv' every ::1 using 2:5 with linespoints pt 7 ps 0.5 notitle
set xlabel 'starting angle th1 (rad)'
set ylabel '|E(10) - E(0)| (J)'
set logscale y
set format y '%.0e'
plot 'ensemble-sweep.csv' every ::1 using 2:(abs($9)) with linespoints pt 7 ps 0.5 notitle
unset multiplot
