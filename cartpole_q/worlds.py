"""Kept so that ids written ``cartpole_q.worlds:cartpole_q/Name-v0`` still make.

The package's worlds now live in their families (:mod:`cartpole_q.families`), and importing
any module of the package registers them with Gymnasium (:mod:`cartpole_q.families.registration`);
Gymnasium imports the module an id names before its ``:``, so this module is all an id of
that form needs. Run directories record their ``env.id`` as it was written.
"""
