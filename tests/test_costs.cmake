# Seconds that the suite's longest tests take on the CI machine type (two cores, Release build;
# under ASan they take 2-4 times as long), measured in session 25. CTest starts the costliest
# tests first (the COST property; with no history, as on the CI's fresh machine, every other test
# costs 0 and they run in the order they were added): a long test that started last would run
# alone at the end while the other core idled (the 126 s FluidBooks test finished 697th of 698).
# Read by the label script of each GoogleTest target (tests/CMakeLists.txt), at CTest time.
set(SEEP_TEST_COSTS
    FluidBooks.TenThousandDiskFracturingClosesItsBalance=126
    RemoteWorkers.TwoWorkersDrainATwentyJobSweepThroughTwoSigkillsBitIdentical=46
    ClientExamples.EveryExampleSucceedsOnARealSeepd=23
    Chaos.TwentyTwoJobsSurviveSeededSigkillsBitIdentical=16
    CrashRecovery.SigkillAtRandomPointsEndsBitIdenticalToAnUninterruptedRun=10
    StagedExamples.AnisotropicFracturingBreaksDownAndRunsAlongSigmaH=10
    CrashRecovery.SigtermCheckpointsAndACancelledJobResumesWhereItStopped=9
    Stages.ForksFromAPreparedSampleBreakDownInTheOrderOfTheirRates=9
    ServiceHeal.AHungWorkersJobIsRescuedAndEndsBitIdentical=9
    V17Terzaghi.ColumnConsolidatesAsTerzaghiPredicts=6
    ServiceOperations.RetentionDeletesWhatItShouldAndNothingElse=6)
