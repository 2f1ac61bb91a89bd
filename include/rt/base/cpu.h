/* rt/base/cpu.h - how many processors this process may run on.
 *
 * The count a default thread pool should use: the CPUs of the process's
 * affinity mask (what taskset, cgroup cpusets, Slurm and Kubernetes CPU
 * pinning leave it), not every core of the machine; 1 to 1024.
 *
 *   int threads = opt.threads > 0 ? opt.threads : rt_cpu_count();
 */
#ifndef RT_CPU_H
#define RT_CPU_H

int rt_cpu_count(void);

#endif
