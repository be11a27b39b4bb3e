# svo: a deliberately undersized node pool stops the build with one line naming the pool and the size it needs.
voxlab_cli_case(svo_node_pool_overflow 2 "svo-build: node pool overflow at level 1: it holds 4 nodes, the level needs 9" "run --technique svo --set voxel.resolution=16 --set svo.pool-fraction=0.5 --final-only --out @OUT@")
